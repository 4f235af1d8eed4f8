"""The sub-command parser shape every command uses: one-line help, a description and worked examples (kept
here, below the CLI, so that commands do not import approachsim.cli: the layers contract)."""

from __future__ import annotations

import argparse
from collections.abc import Sequence


def command_parser(
    sub: argparse._SubParsersAction, name: str, *, help: str, description: str, examples: Sequence[str]
) -> argparse.ArgumentParser:
    """A sub-command parser with a one-line `help` (top-level list), a `description` and worked `examples`."""
    return sub.add_parser(
        name, help=help, description=description,
        epilog="example" + ("s" if len(examples) > 1 else "") + ":\n" + "\n".join(f"  {e}" for e in examples),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
