"""nav/noise.py's gyro scale-factor / misalignment process noise: q_k = sf^2 D_k + mis^2 E_k per body axis from the
grade and the turbulence level's unbounded scale-factor attitude error (SF_DRIFT_Q), rotated into NED on top of the
ARW."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile

DEFAULT = Path(__file__).resolve().parents[3] / "profiles" / "default.toml"


def test_gyro_axis_noise_is_the_grade_times_the_body_rotation():
    """Default profile (nav-2.0: 100 ppm, 0.02 mrad; light turbulence: per unit sf^2 2.20e-6, 4.02e-5, 2.05e-6 and
    per unit mis^2 3.15e-5, 4.14e-6, 2.80e-5 rad^2/s), written out; calm air gives none."""
    nav = NavSystem.from_profile(load_profile(DEFAULT))
    assert nav.turbulence == "light"
    want = 1e-4**2 * np.array([2.20e-6, 4.02e-5, 2.05e-6]) + 2e-5**2 * np.array([3.15e-5, 4.14e-6, 2.80e-5])
    nz = nav.noise_model.noise(None)
    np.testing.assert_allclose([nz.gyro_axis_q_x, nz.gyro_axis_q_y, nz.gyro_axis_q_z], want, rtol=1e-12)
    assert want[1] > 100 * nz.gyro_arw_rad_sqrts**2  # the pitch axis (the Dutch roll's coning): ~170 x the ARW^2
    calm = replace(nav, turbulence="none").noise_model.noise(None)
    assert (calm.gyro_axis_q_x, calm.gyro_axis_q_y, calm.gyro_axis_q_z) == (0.0, 0.0, 0.0)


def test_gyro_axis_noise_enters_the_attitude_in_body_axes():
    """The kernel's attitude block of Qc is ARW^2 I + C diag(q) C' (C body to NED) at a rotated attitude, and
    nothing else changes with it."""
    nav = NavSystem.from_profile(load_profile(DEFAULT))
    lay, nz = nav.layout, nav.noise_model.noise(None)
    c = ins.cbn_from_euler(np.array([0.3, -0.1, 2.0]))
    args = (lay, 0.65, 300.0, np.array([60.0, -30.0, 3.0]), np.array([0.1, 0.2, -9.8]), c)
    F, Qc = em.dynamics(*args, nz, nav.loop_gains())
    F0, Q0 = em.dynamics(*args, replace(nz, gyro_axis_q_x=0.0, gyro_axis_q_y=0.0, gyro_axis_q_z=0.0),
                         nav.loop_gains())
    a = lay.index["psi"]
    q = np.diag([nz.gyro_axis_q_x, nz.gyro_axis_q_y, nz.gyro_axis_q_z])
    np.testing.assert_allclose(Qc[a, a] - Q0[a, a], c @ q @ c.T, rtol=1e-9, atol=1e-27)
    d = Qc - Q0
    d[a, a] = 0.0
    assert not d.any() and np.array_equal(F, F0)
