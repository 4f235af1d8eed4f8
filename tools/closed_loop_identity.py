"""Bit-identity check of the closed loop (navigation in the loop): fly every shipped profile (profiles/*.toml) x 2
runs with NavInTheLoop and save, or compare with np.array_equal against a saved file, every array of the
FlightResult (truth, guidance, ...) and the NavRun (solution, filter history, status log).

    python tools/closed_loop_identity.py save /tmp/main.npz       # on the reference commit
    python tools/closed_loop_identity.py compare /tmp/main.npz    # on the changed code: exit 1 on any difference
"""

from __future__ import annotations

import dataclasses
import os
import sys
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _arrays(prefix: str, obj, out: dict) -> None:
    """Every numeric array reachable through obj's dataclass fields, keyed by their path."""
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fiub":
            out[prefix] = obj
        elif obj.dtype.kind in "UO":
            out[prefix] = obj.astype(str)
        return
    if isinstance(obj, (int, float, bool, np.number)):
        out[prefix] = np.asarray(obj)
        return
    if dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            _arrays(f"{prefix}.{f.name}", getattr(obj, f.name), out)
    elif isinstance(obj, dict):
        for k, v in obj.items():
            _arrays(f"{prefix}[{k}]", v, out)
    elif isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj):
            _arrays(f"{prefix}[{i}]", v, out)


def fly_all() -> dict[str, np.ndarray]:
    """Every profile's closed loop, runs 0 and 1 of seed 1: their arrays by name."""
    from approachsim.flight.run import Approach
    from approachsim.loop.closed_loop import NavInTheLoop
    from approachsim.profile import load_profile

    out: dict[str, np.ndarray] = {}
    for path in sorted((ROOT / "profiles").glob("*.toml")):
        prof = load_profile(path)
        a = Approach(prof)
        for run in (0, 1):
            src = NavInTheLoop(prof, seed=1, run=run, max_time_s=a.time_budget_s)
            res = a.fly(seed=1, run=run, nav_source=src)
            nav = src.result(res.truth)
            key = f"{path.stem}/{run}"
            _arrays(key + "/flight", res, out)
            _arrays(key + "/nav", nav, out)
            print(f"{key}: {len(res.truth)} rows, {len(nav.t_epoch_s)} epochs, fast epochs "
                  f"{src._fast is not None}, direct inputs {src._fast is not None and src._fast.direct}", flush=True)
    return out


def main() -> int:
    what, path = sys.argv[1], sys.argv[2]
    got = fly_all()
    if what == "save":
        np.savez(path, **got)
        print(f"saved {len(got)} arrays")
        return 0
    ref = dict(np.load(path))
    bad = sorted(set(ref) ^ set(got))
    for k in sorted(set(ref) & set(got)):
        if ref[k].shape != got[k].shape or not np.array_equal(ref[k], got[k], equal_nan=ref[k].dtype.kind == "f"):
            bad.append(k)
    print(f"{len(ref)} arrays compared, {len(bad)} differ" + ("".join(f"\n  {b}" for b in bad[:40])))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
