"""The navigation's mean height error along the approach, over open-loop runs: the systematic part of the vertical
error (docs/baro-loop-hold-bias.md).

    python tools/vertical_bias.py PROFILE [PROFILE ...] [--groups 4] [--geometric-baro]

For each profile, `--groups` flight groups of 25 runs through campaign.pipeline.open_loop_group; at heights above
the threshold from 9000 ft down to 50 ft prints the mean over the runs of h_nav - h_true (m), its RMS and the
filter's own vertical sigma (RMS of sqrt(P_DD)), and the four groups' means at 1000 and 200 ft (each group has its
own truth). --geometric-baro converts the baro's indication (ISA geopotential height) to geometric height before
the navigation sees it, which removes the geopotential part of the baro error (-z^2 / r0, 1.6 m at 10,400 ft).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

HEIGHTS_FT = np.array([9000, 7000, 5000, 3000, 2500, 2000, 1500, 1000, 600, 400, 200, 100, 50], dtype=float)
FT = 0.3048


def _row(values: np.ndarray, have: np.ndarray, fmt: str) -> str:
    """One table row: the values where the approach reached that height, '-' elsewhere."""
    return " ".join(f"{v:{fmt}}" if h else "     -" for v, h in zip(values, have, strict=True))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profiles", nargs="+")
    ap.add_argument("--groups", type=int, default=4)
    ap.add_argument("--geometric-baro", action="store_true")
    args = ap.parse_args()

    from approachsim import geo
    from approachsim.campaign import pipeline
    from approachsim.profile import load_profile
    from approachsim.sensors import atmosphere
    from approachsim.sensors.suite import SensorSuite

    if args.geometric_baro:
        apply = SensorSuite.apply

        def geometric(self, truth, errors):
            rec = apply(self, truth, errors)
            if rec.get("baro") is not None:
                H = np.asarray(rec["baro"].h_baro_m)
                r0 = atmosphere.R_EARTH_GEOPOT_M
                rec["baro"] = dataclasses.replace(rec["baro"], h_baro_m=r0 * H / (r0 - H))
            return rec

        SensorSuite.apply = geometric
    caught: list = []
    score = pipeline._score

    def spy(profile, i, truth, sol, *a, **k):
        _, _, h = geo.ecef_to_geodetic(sol.r_ecef)
        n = len(h)
        caught.append((np.asarray(truth.r_rwy[:n, 2]), h - np.asarray(truth.h_m[:n]),
                       np.sqrt(np.asarray(sol.P_pos_ned)[:, 2, 2])))
        return score(profile, i, truth, sol, *a, **k)

    pipeline._score = spy
    x = HEIGHTS_FT * FT
    for path in args.profiles:
        caught.clear()
        prof = load_profile(path)
        for g in range(args.groups):
            pipeline.open_loop_group(prof, 1, list(range(25 * g, 25 * g + 25)))
        err, sig = [], []
        for hat, dh, s in caught:
            o = np.argsort(hat)
            err.append(np.interp(x, hat[o], dh[o], left=np.nan, right=np.nan))
            sig.append(np.interp(x, hat[o], s[o], left=np.nan, right=np.nan))
        err, sig = np.array(err), np.array(sig)
        have = ~np.all(np.isnan(err), axis=0)
        print(f"{path}: {len(caught)} runs, h_nav - h_true (m){' (geometric baro)' if args.geometric_baro else ''}")
        print("  height ft:", " ".join(f"{h:6.0f}" for h in HEIGHTS_FT))
        with warnings.catch_warnings():  # all-nan columns: heights above the start
            warnings.simplefilter("ignore", RuntimeWarning)
            print("  mean     :", _row(np.nanmean(err, 0), have, "+6.2f"))
            print("  rms      :", _row(np.sqrt(np.nanmean(err ** 2, 0)), have, "6.2f"))
            print("  sigma    :", _row(np.sqrt(np.nanmean(sig ** 2, 0)), have, "6.2f"))
            groups = np.array([np.nanmean(err[25 * g:25 * g + 25], 0) for g in range(args.groups)])
        i1000, i200 = list(HEIGHTS_FT).index(1000), list(HEIGHTS_FT).index(200)
        print(f"  group means at 1000 ft {np.round(groups[:, i1000], 2)}, at 200 ft {np.round(groups[:, i200], 2)}")


if __name__ == "__main__":
    main()
