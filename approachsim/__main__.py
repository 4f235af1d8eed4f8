"""`python -m approachsim` runs the command line."""

from approachsim.cli import run

run()
