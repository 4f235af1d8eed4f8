"""The flown airframe's body-rate spectrum in the aided filter's band: the source of nav/noise.py BODY_RATE_PSD.

    python tools/body_rate_psd.py PROFILE [--seeds 1 2 3] [--turbulence light moderate severe]

Flies the profile (run 0 of each seed) at each turbulence level and prints, per body axis (roll, pitch, yaw), the
two-sided power spectral density of the true inertial body rate w_ib (mean removed; Welch, 128 s segments) averaged
over 0.01-0.05 Hz, rad^2/s^2/Hz: periods of 20-100 s, between the 1 s aiding interval and the aided filter's tilt
and velocity time constants, where a gyro scale-factor / misalignment error rate (S + M) w_ib integrates into
attitude error the aiding does not remove at once (the faster turbulence rates average out within their ~1 s
correlation time; the mean rate is zero over a straight-in approach).
"""

from __future__ import annotations

import argparse
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.signal import welch

BAND_HZ = (0.01, 0.05)


def band_psd(w: np.ndarray, dt: float) -> np.ndarray:
    """Two-sided PSD (rad^2/s^2/Hz) of each column of w (n, 3) averaged over BAND_HZ."""
    f, p = welch(w - w.mean(axis=0), fs=1.0 / dt, nperseg=min(len(w), int(round(128.0 / dt))), axis=0)
    m = (f >= BAND_HZ[0]) & (f <= BAND_HZ[1])
    return 0.5 * p[m].mean(axis=0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profile", type=Path)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--turbulence", nargs="+", default=["light", "moderate", "severe"])
    a = ap.parse_args()
    from approachsim.flight.run import Approach
    from approachsim.profile import parse_profile

    data = tomllib.loads(a.profile.read_text(encoding="utf-8"))
    prof0 = parse_profile(data, source=a.profile.resolve())
    for level in a.turbulence:
        prof = replace(prof0, environment=replace(prof0.environment, turbulence=level))
        out = []
        for seed in a.seeds:
            tr = Approach(prof).fly(seed=seed, run=0).truth
            out.append(band_psd(np.asarray(tr.w_ib_body), float(tr.t_s[1] - tr.t_s[0])))
        s = np.mean(out, axis=0)
        print(f"{level:9s} roll {s[0]:.3g} pitch {s[1]:.3g} yaw {s[2]:.3g} rad^2/s^2/Hz (seeds {a.seeds}; "
              f"per seed pitch {', '.join(f'{o[1]:.3g}' for o in out)})")


if __name__ == "__main__":
    main()
