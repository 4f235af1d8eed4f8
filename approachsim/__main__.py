"""`python -m approachsim` runs the command line."""

from approachsim.cli import main

raise SystemExit(main())
