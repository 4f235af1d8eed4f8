"""Bit-identity check of the open loop with the integrity bank: every shipped profile (profiles/*.toml), runs 0-3 of
flight group 0 and runs 25-27 of group 1 through campaign.pipeline.open_loop_group (the campaign's own path:
flight, sensors, navigation, the bank, scoring), and save, or compare with np.array_equal (nan equal to nan)
against a saved file, every scalar, array, series and integrity count of every RunResult.

    python tools/open_loop_identity.py save /tmp/main.npz       # on the reference commit
    python tools/open_loop_identity.py compare /tmp/main.npz    # on the changed code: exit 1 on any difference
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RUNS = ([0, 1, 2, 3], [25, 26, 27])


def collect() -> dict[str, np.ndarray]:
    """Every number of every run's result, keyed by profile/run/kind/name."""
    from approachsim.campaign.pipeline import open_loop_group
    from approachsim.profile import load_profile

    out: dict[str, np.ndarray] = {}
    for path in sorted((ROOT / "profiles").glob("*.toml")):
        prof = load_profile(path)
        for runs in RUNS:
            for r in open_loop_group(prof, 1, runs):
                key = f"{path.stem}/{r.run}"
                out[f"{key}/ok"] = np.array([r.ok])
                out[f"{key}/error"] = np.array([r.error or ""])
                for kind in ("scalars", "arrays", "series", "counts"):
                    for name, v in (getattr(r, kind) or {}).items():
                        out[f"{key}/{kind}/{name}"] = np.asarray(v)
    return out


def main() -> int:
    if len(sys.argv) != 3 or sys.argv[1] not in ("save", "compare"):
        print(__doc__)
        return 2
    got = collect()
    if sys.argv[1] == "save":
        np.savez(sys.argv[2], **got)
        print(f"saved {len(got)} arrays to {sys.argv[2]}")
        return 0
    ref = dict(np.load(sys.argv[2]))
    differ = [k for k in sorted(set(ref) | set(got)) if k not in ref or k not in got
              or ref[k].shape != got[k].shape
              or not np.array_equal(ref[k], got[k], equal_nan=ref[k].dtype.kind in "fc")]
    for k in differ[:20]:
        print("differs:", k)
    print(f"{len(got)} arrays, {len(differ)} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
