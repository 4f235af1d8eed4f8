"""Command line: `approachsim fly | sense | navigate | evaluate | merge | integrity-risk | study | regress | reproduce |
profiles`.

Each sub-command lives in its own module under approachsim/commands/, with `register(subparsers)`; evaluate, merge,
study and integrity-risk are thin layers over the Python API (approachsim/api.py).
User mistakes (bad profile, bad option) exit with status 2 and one line naming the field, never a traceback.
"""

from __future__ import annotations

import argparse
import atexit
import importlib
import os
import sys
import threading
from collections.abc import Sequence
from typing import NoReturn

from approachsim.commands._help import command_parser  # noqa: F401  (re-exported)
from approachsim.config import ProfileError

COMMAND_MODULES = (
    "approachsim.commands.fly",
    "approachsim.commands.sense",
    "approachsim.commands.navigate",
    "approachsim.commands.reproduce",
    "approachsim.commands.evaluate",
    "approachsim.commands.merge",
    "approachsim.commands.integrity_risk",
    "approachsim.commands.study",
    "approachsim.commands.regress",
    "approachsim.commands.profiles",
)
"""Modules that each add sub-commands; a new command adds its line here."""


class _OneLineParser(argparse.ArgumentParser):
    """argparse that reports a bad option as one line and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


EPILOG = """start here:
  approachsim profiles                              the shipped profiles
  approachsim profiles init default ~/approaches    copy one to edit (keys: docs/profiles.md)
  approachsim evaluate ~/approaches/default.toml    Monte Carlo verdict against CAT I / II / III
`approachsim COMMAND --help` describes each command with an example."""


def version() -> str:
    """The installed package version (the source tree's pyproject version when run uninstalled)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as dist_version

    try:
        return dist_version("approachsim")
    except PackageNotFoundError:
        return "unknown (not installed)"


def build_parser() -> argparse.ArgumentParser:
    """The full parser with every stage's sub-commands."""
    parser = _OneLineParser(
        prog="approachsim",
        description="Precision-approach navigation simulator: fly a JSBSim approach, model the sensors, run the\n"
        "INS + filter, and score Monte Carlo campaigns against FAA CAT I / II / III.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"approachsim {version()}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_OneLineParser)
    for mod in COMMAND_MODULES:
        importlib.import_module(mod).register(sub)
    return parser


BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
"""Set to 1 by the console script unless the user set them (main): campaigns use one process per core, and BLAS
threads would oversubscribe the cores (OpenBLAS's idle threads spin on them)."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `approachsim` console script; returns the exit status."""
    for var in BLAS_THREAD_VARIABLES:  # before numpy loads its BLAS (the command modules import it)
        os.environ.setdefault(var, "1")
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ProfileError as e:
        sys.stderr.write(f"approachsim: error: {e}\n")
        return 2
    except FileNotFoundError as e:  # a file the command needed: one line naming it (or where it was looked for)
        from approachsim.campaign.runner import missing_path_note

        sys.stderr.write(f"approachsim: error: {e}{missing_path_note(e)}\n")
        return 2
    except BrokenPipeError:  # output piped into `head` and the like: stop quietly (Python docs, signal note)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1


def run() -> NoReturn:
    """The console script (and `python -m approachsim`): main(), then the exit handlers Python registered (atexit),
    the standard streams flushed, and the process ends with main's status without the interpreter's teardown.
    Every command has written and closed its files before main returns; what the teardown would add is freeing
    each object and module of numpy, scipy, numba and matplotlib one by one: about 0.4 s at the end of every
    command (an evaluate included), for nothing the user sees. An exception out of main, or a thread still
    running that Python would wait for, takes Python's own path."""
    code = main()
    run_exitfuncs = getattr(atexit, "_run_exitfuncs", None)  # CPython's; without it, Python's own exit
    others = [t for t in threading.enumerate() if t is not threading.main_thread() and not t.daemon]
    if run_exitfuncs is None or others:  # a thread Python would wait for (none after our commands): its own exit
        raise SystemExit(code)
    run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed or broken pipe: nothing more to say
            pass
    os._exit(code)


if __name__ == "__main__":
    run()
