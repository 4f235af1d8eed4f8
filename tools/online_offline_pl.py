"""The online FDE's protection levels against the offline solution-separation bank's on the same flights
(docs/integrity.md, "Online and offline protection levels").

    python tools/online_offline_pl.py [--runs 3] [--category "CAT I"] [--start-nmi 5]

The default profile with all satellites in view (the bank needs redundancy), the online FDE on with the category's
allocation, fault-free: JSBSim flies each run closed loop on the FDE's solution; the bank then re-navigates the
truth it flew (campaign.integrity_bank.run_bank). Both PLs come from integrity.protection with the same K factors; they
differ in the fault they bound (one arriving at this epoch, detected by the residual test; one persisting over the
run, detected by the separation test). Prints, per axis, the median and range of online / offline over the
category's window (from 1000 ft down to its decision height), and both at the decision height.
"""

from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from approachsim import units  # noqa: E402
from approachsim.campaign.integrity_bank import run_bank, score_category  # noqa: E402
from approachsim.flight.run import Approach  # noqa: E402
from approachsim.integrity.requirements import REQUIREMENTS  # noqa: E402
from approachsim.loop.closed_loop import NavInTheLoop  # noqa: E402
from approachsim.profile import parse_profile  # noqa: E402

DEFAULT = ROOT / "profiles" / "default.toml"
DH_FT = {"CAT I": 200.0, "CAT II": 100.0, "CAT III": 50.0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--category", default="CAT I", choices=list(REQUIREMENTS))
    ap.add_argument("--start-nmi", type=float, default=5.0)
    a = ap.parse_args()
    d = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    d["runway"]["start_distance_nmi"] = a.start_nmi
    d["sensors"]["gnss"]["selection"] = "all"
    d["nav"]["fde"] = {"enabled": True, "category": a.category}
    prof = parse_profile(d, source=DEFAULT)
    req = REQUIREMENTS[a.category]
    ratios, at_dh, h1h0 = [], [], []
    for run in range(a.runs):
        src = NavInTheLoop(prof, seed=a.seed, run=run)
        res = Approach(prof).fly(seed=a.seed, run=run, nav_source=src)
        nav = src.result(res.truth)
        ep, _ = run_bank(prof, res.truth, a.seed, run)
        window = (ep.height_m <= 1000.0 * units.FT) & (ep.height_m >= DH_FT[a.category] * units.FT)
        off = score_category(ep, req, prof.nav.aiding_rate_hz, window)
        rows = np.searchsorted(res.truth.t_s, np.asarray(nav.t_epoch_s) - 1e-9)
        on = np.asarray(nav.solution.protection_level_m)[rows]
        # the bank's epochs are the navigation's epochs (the same schedule): align by time
        t_on = np.asarray(nav.t_epoch_s)
        idx = np.searchsorted(t_on, ep.t_s[window] - 1e-6)
        ok = (idx < t_on.size) & (np.abs(t_on[np.minimum(idx, t_on.size - 1)] - ep.t_s[window]) < 1e-3)
        r = on[idx[ok]] / off.pl_m[ok]
        ratios.append(r)
        h1h0.append(off.result.pl_h1_m[ok] / off.result.pl_h0_m[ok])
        at_dh.append((on[idx[ok]][-1], off.pl_m[ok][-1], res.termination))
        print(f"run {run}: {res.termination}; {int(ok.sum())} epochs; at the DH online {on[idx[ok]][-1].round(2)} m,"
              f" offline {off.pl_m[ok][-1].round(2)} m (vertical, lateral)")
    r = np.concatenate(ratios)
    for i, axis in enumerate(("vertical", "lateral")):
        q = np.nanpercentile(r[:, i], [0, 50, 100])
        print(f"{axis}: online / offline PL median {q[1]:.3f}, range [{q[0]:.3f}, {q[2]:.3f}] over {r.shape[0]} epochs")
        h = np.nanpercentile(np.concatenate(h1h0)[:, i], [0, 50, 100])
        print(f"  offline PL_H1 / PL_H0 median {h[1]:.3f}, range [{h[0]:.3f}, {h[2]:.3f}]")
    print(f"(category {a.category}, K_ff {req.k_ff():.2f}, K_md {req.k_md():.2f}; {len(at_dh)} runs)")


if __name__ == "__main__":
    main()
