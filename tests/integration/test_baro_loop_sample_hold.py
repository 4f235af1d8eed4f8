"""Known defect (docs/baro-loop-hold-bias.md): the baro damping loop's sample-and-hold biases the height on a descent.

The strapdown INS closes its third-order baro loop (Sokolovic et al. eq. 5) on the last baro sample, held over
the IMU intervals until the next one (nav/kernels/strapdown.py; integrity/bankpass._baro_held). On a descent at
V m/s the held sample is, on average, V dt_baro / 2 above the aircraft (measured: 0.22-0.24 s of staleness at
2 Hz). The loop makes the INS track it, and the filter's error model (a loop driven by the baro's own errors)
has no term for the lag, so the navigation reads high by a deterministic amount its covariance does not cover:
on the default profile from 10 nmi, +0.26 m at the CAT I decision height with the default 10 Hz baro (+0.6 m
after a 30 nmi final), +1.4 m with a 2 Hz baro, against a vertical sigma of 0.6 m. High is the hazardous side
of a decision height. Without the loop, or with a 120 Hz baro, the mean error is within its noise.

Open loop, one flown truth, 25 runs, integrity bank off; the runs share the truth, so the lag's part of the
error is the same in every run and the mean over the runs carries it, with a standard error of about
sd / 5 = 0.14 m from the runs' own errors. A 2 Hz baro makes the bias large enough to see in 25 runs.
"""

from __future__ import annotations

import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from approachsim.campaign.pipeline import open_loop_group
from approachsim.profile import parse_profile

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = ROOT / "profiles" / "default.toml"

pytestmark = pytest.mark.slow

BOUND_M = 0.45
"""|mean error| allowed over 25 runs: about 3.3 standard errors of the mean (sd 0.63-0.68 m / 5)."""


def _mean_vertical_at_cat1_dh(loop: str) -> tuple[float, float]:
    data = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    data["sensors"]["baro"]["rate_hz"] = 2.0
    data["nav"]["baro_loop"] = loop
    prof = parse_profile(data, source=DEFAULT)
    prof = replace(prof, evaluation=replace(prof.evaluation, integrity=()))
    res = open_loop_group(prof, 1, list(range(25)))
    assert all(r.ok for r in res)
    v = np.array([r.scalars["cat1_vertical_m"] for r in res])
    return float(v.mean()), float(v.std(ddof=1))


def test_without_the_loop_the_height_is_unbiased():
    mean, sd = _mean_vertical_at_cat1_dh("none")
    assert abs(mean) < BOUND_M, (mean, sd)


@pytest.mark.xfail(strict=True, reason="known defect: the baro loop's held sample lags on a descent and the filter "
                   "does not model it (docs/baro-loop-hold-bias.md); measured +1.4 m at the CAT I DH with a 2 Hz baro")
def test_with_the_loop_the_height_is_unbiased():
    mean, sd = _mean_vertical_at_cat1_dh("constant")
    assert abs(mean) < BOUND_M, (mean, sd)
