"""Issue 26 item 2: the 3 m radar-altimeter bias near the ground. Is it detected, or bounded by the protection
level? Open loop on flown default approaches (campaign.integrity_risk's sampler), the bias starting ONSET s before the
lowest decision height, GPS-only bank and the bank with the sensor modes (the radar altimeter a fault mode).

    PYTHONPATH=. python benchmarks/radalt_bias_near_ground.py [--runs 30] [--bias-m 3] [--onset-s 60] [--workers 2]

Prints per category and bank: runs, runs detected, radar altimeter excluded, runs with a misleading (error > PL) or
hazardously misleading epoch, the largest vertical error of the output and the median vertical PL at the DH.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.stats import norm

from approachsim.campaign.bank_modes import RADALT_MODE
from approachsim.campaign.integrity_risk import MODES, Simulator, _columns
from approachsim.profile import load_profile


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--profile", default="profiles/default.toml")
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--bias-m", type=float, default=3.0)
    ap.add_argument("--onset-s", type=float, default=60.0)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    profile = load_profile(a.profile)
    mode = MODES["radalt-bias"]
    for sensor_modes in (False, True):
        with Simulator(profile, a.seed, 4, a.workers, sensor_modes) as sim:
            from approachsim.campaign.integrity_risk import flight_truth

            _, lo, hi = flight_truth(profile, a.seed, 0)
            frac = min(max((hi - a.onset_s - lo) / (hi - lo), 1e-9), 1 - 1e-9)
            m = (np.log(a.bias_m) - np.log(mode.low)) / (np.log(mode.high) - np.log(mode.low))
            u = np.tile([norm.ppf(frac), norm.ppf(m)], (a.runs, 1))
            t = time.time()
            c = _columns(sim.run(mode.name, 7_000_000 + np.arange(a.runs), u))
            print(f"bank {'with sensor modes' if sensor_modes else 'GPS only'}: {a.runs} runs, {a.bias_m} m bias "
                  f"{a.onset_s:.0f} s before the lowest DH ({time.time() - t:.0f} s); bias applied "
                  f"{np.nanmedian(c['fault_magnitude']):.2f} m")
            for key in ("cat1", "cat2", "cat3"):
                det = int(np.sum(c[f"{key}_detected"] > 0))
                exc = int(np.sum(c[f"{key}_excluded"] == RADALT_MODE))
                n_mi, n_hmi = int(np.sum(c[f"{key}_mi"] > 0)), int(np.sum(c[f"{key}_hmi"] > 0))
                v = c[f"{key}_vmax_m"]
                print(f"  {key}: detected {det}, radalt excluded {exc}, runs with MI {n_mi}, with HMI {n_hmi}, "
                      f"largest vertical error {np.nanmax(v):.2f} m (median {np.nanmedian(v):.2f}), largest MI "
                      f"margin (|e| - PL) {np.nanmax(c[f'{key}_mi_g']):.2f} m", flush=True)


if __name__ == "__main__":
    main()
