"""Filter consistency (issue 4 acceptance): default profile sensors, 100 seeded runs on one shared synthetic
glidepath truth (open loop). At each aiding epoch the run-averaged NEES of the 9 navigation errors and the
run-averaged NIS of each measurement group must lie inside their two-sided 95 % chi-square bounds for at
least 90 % of the epochs (Bar-Shalom, Li & Kirubarajan sec. 5.4). A filter that claims a sigma it does not
have fails here.

The default start is the converged pre-approach state (nav/initial.py): the first epochs are checked on their own
too, since an independent diagonal prior would make them easy and a wrong conditioning shows there first.
The default profile carries the radar altimeter's bias and Markov error and a terrain database that differs from
the truth terrain (bias + along-track Gauss-Markov, crossing the Area 4 boundary 900 m before the threshold);
the filter models them with its rab / ram / tdb states, and the bounds must still hold."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.stats import chi2

from approachsim import synthetic
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[2] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""

RUNS = 100
SEED = 1


@pytest.fixture(scope="module")
def runs():
    prof = load_profile(PY_DEFAULT)
    ra, db = prof.sensors.radalt, prof.nav.terrain_database
    assert ra.bias_sigma_m > 0 and ra.markov_sigma_m > 0 and db.bias_sigma_m > 0 and db.correlated  # not white
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=10.0, start_distance_m=70.0 * 90.0,
                                        ground_speed_mps=70.0)
    assert prof.nav.initial_error.start == "converged"
    recs, st = measure_with_states(SensorSuite.from_profile(prof), truth, seed=SEED, runs=list(range(RUNS)))
    return NavSystem.from_profile(prof).run(truth, recs, [stream(SEED, r, "nav") for r in range(RUNS)], states=st)


def _nees(runs):
    e = np.stack([r.true_error_nav for r in runs])  # (runs, epochs, 9): output - truth = -(x_hat - x)
    P = np.stack([r.P_nav for r in runs])
    return np.einsum("rki,rki->rk", e, np.linalg.solve(P, e[..., None])[..., 0]).mean(axis=0)


@pytest.mark.slow
def test_average_nees_inside_95_percent_bounds(runs):
    nees = _nees(runs)
    lo, hi = chi2.ppf([0.025, 0.975], 9 * RUNS) / RUNS
    inside = (nees >= lo) & (nees <= hi)
    assert inside.mean() >= 0.9, (nees.mean(), inside.mean())


@pytest.mark.slow
def test_first_ten_epochs_nees_inside_bounds(runs):
    """Each of the first 10 epochs inside its two-sided 99 % bound, and their mean inside the single-epoch 95 %
    bound (conservative: the epochs are positively correlated)."""
    nees = _nees(runs)[:10]
    lo99, hi99 = chi2.ppf([0.005, 0.995], 9 * RUNS) / RUNS
    lo, hi = chi2.ppf([0.025, 0.975], 9 * RUNS) / RUNS
    assert np.all((nees >= lo99) & (nees <= hi99)), nees
    assert lo <= nees.mean() <= hi, nees.mean()


@pytest.mark.slow
@pytest.mark.parametrize("group", ["baro", "radalt", "gps"])
def test_average_nis_inside_95_percent_bounds(runs, group):
    by_epoch: dict[float, list[float]] = {}
    for r in runs:
        m = np.char.startswith(r.status.name, group)
        for t, q in zip(r.status.t_s[m], r.status.test_ratio[m], strict=True):
            by_epoch.setdefault(round(float(t), 6), []).append(float(q))
    assert len(by_epoch) >= 80  # the group really was used at (almost) every 1 s epoch
    inside = []
    for v in by_epoch.values():
        lo, hi = chi2.ppf([0.025, 0.975], len(v)) / len(v)
        inside.append(lo <= np.mean(v) <= hi)
    assert np.mean(inside) >= 0.9, np.mean(inside)
