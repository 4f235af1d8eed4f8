"""CLI sub-commands, one module each (`register(subparsers)`): the edge where stages are composed."""
