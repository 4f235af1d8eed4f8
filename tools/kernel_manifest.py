"""Record a kernel manifest (approachsim/core/warm.py): the top-level numba compilations of one kind of run, made on
a cold cache, with the CPU seconds each took. Rerun after a change to a kernel's arguments or a call site's types
(tests/unit/test_core_warm.py says when).

    python tools/kernel_manifest.py [closed|open]   # one closed- (open-) loop run of profiles/default.toml

It runs in a fresh, empty numba cache directory (the compile times are a cold cache's) and takes about a minute.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
_DEFAULT = ["evaluate", str(ROOT / "profiles" / "default.toml"), "--runs", "1", "--workers", "1", "--seed", "1",
            "--no-report"]
WORKLOADS = {"closed": _DEFAULT, "open": [*_DEFAULT, "--mode", "open"]}


def main(kind: str = "closed") -> int:
    """Record the `kind` manifest and write it beside core/warm.py; prints what it holds."""
    os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="approachsim-manifest-")
    import numba

    from approachsim.cli import main as cli
    from approachsim.core import warm

    with tempfile.TemporaryDirectory() as out, warm.record() as found:
        code = cli([*WORKLOADS[kind], "--out", out])
    if code not in (0, 1):
        print(f"the {kind} workload failed (exit {code}); manifest not written", file=sys.stderr)
        return 1
    path = warm.save(kind, found, numba.__version__)
    for e in sorted(found, key=lambda e: -e.cost_s):
        print(f"{e.cost_s:6.2f} s  {e.module}.{e.name}")
    print(f"{len(found)} compilations, {sum(e.cost_s for e in found):.1f} s CPU -> {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
