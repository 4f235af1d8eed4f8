"""Per-run GPS skies in the navigation filter: the channel states' process noise follows each run's elevations."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from approachsim.nav import errormodel as em
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.sensors.gnss.receiver import do253_multipath_sigma_m

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


def test_per_class_channel_qd_equals_the_discretized_model_at_that_sky():
    """The shared-covariance path builds Phi, Qd once and resets the GPS channel states' Qd entries to a class's
    own elevations; that must equal discretizing the error model with that sky's noise (the gse / gmp states
    are decoupled first-order Markov states), and the gmp entries follow the DO-253 sigma at each elevation."""
    nav = NavSystem.from_profile(load_profile(PY_DEFAULT))
    lay = nav.layout
    assert lay.has("gse")
    rng = np.random.default_rng(3)
    el1, el2 = np.radians(rng.uniform(3.0, 88.0, 24)), np.radians(rng.uniform(3.0, 88.0, 24))
    c_bn = np.eye(3)
    args = (lay, np.radians(37.6), 300.0, np.array([60.0, -20.0, 3.0]), np.array([0.0, 0.0, -9.8]), c_bn)

    def qd_at(el):
        F, Qc = em.dynamics(*args, nav.noise(el), nav.loop_gains())
        return em.discretize(F, Qc, 1.0)

    phi1, qd1 = qd_at(el1)
    phi2, qd2 = qd_at(el2)
    np.testing.assert_array_equal(phi1, phi2)  # the sky changes only the noise
    assert not np.allclose(qd1, qd2)
    np.testing.assert_allclose(nav.noise_model.channel_qd(qd1, el2, 1.0), qd2, rtol=1e-12, atol=0.0)
    k = np.arange(lay.index["gmp"].start, lay.index["gmp"].stop)
    tau = nav.sensors.gnss.budget().multipath_tau_s
    np.testing.assert_allclose(qd2[k, k], do253_multipath_sigma_m(el2) ** 2 * -np.expm1(-2.0 / tau), rtol=1e-12)
