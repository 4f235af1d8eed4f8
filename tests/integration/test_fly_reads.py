"""What the flight loop reads from JSBSim and what it derives instead (core/loop/flight_step.py, flight/fdm.LoopIO).

JSBSim's Earth-relative body rates (velocities/p-rad_sec, ...) are not read: the loop derives them from the inertial
rates and the attitude, w_eb = w_ib - C_nb' w_ie at the geodetic latitude (kernels.earth_rates_reference). JSBSim
computes them with its ECI quaternion's matrix, which it lets drift from unit norm by up to 1e-10 before it
renormalizes (FGQuaternion::Normalize), so the two differ by up to 2e-10 Omega_E = 1.5e-14 rad/s (measured over
this test's manoeuvres: 8.6e-15 rad/s); with the geocentric latitude they would differ by 1e-7 rad/s.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from approachsim import geo
from approachsim.core import layouts
from approachsim.core.loop import flight_step as fk
from approachsim.flight import vectors as fv
from approachsim.flight.fdm import FDM
from approachsim.flight.run import Approach
from approachsim.profile import load_profile

pytestmark = pytest.mark.slow

DEFAULT = Path(__file__).resolve().parents[2] / "tests" / "data" / "default-py.toml"
RATE_BOUND = 2.0e-10 * geo.OMEGA_JSBSIM + 1e-16
"""JSBSim's |q|^2 - 1 stays within 2e-10 (renormalized at |1 - |q|| >= 1e-10), rad/s."""


@pytest.fixture(scope="module")
def manoeuvre():
    """3000 steps (25 s) from the default profile's trimmed start with rolling and pitching inputs: the loop's reads
    (LoopIO) and JSBSim's own p, q, r and geocentric latitude at every step."""
    approach = Approach(load_profile(DEFAULT))
    fdm = FDM(approach.aircraft.jsbsim_model, approach.dt_s)
    approach._trim(fdm, approach.start())
    io = fdm.loop_io(layouts.RAW_FIELDS, layouts.GEAR_FIELDS, layouts.GEAR_AIRBORNE)
    own = [fdm.node(f"velocities/{c}-rad_sec").get_double_value for c in "pqr"]
    lat_gc = fdm.node("position/lat-gc-rad").get_double_value
    raw, pqr, gc, near = [], [], [], []
    for k in range(3000):
        io.set_aileron(0.3 * math.sin(k / 50.0))
        io.set_elevator(0.1 * math.sin(k / 37.0))
        io.run()
        raw.append(io.read())
        near.append(io.read_near())
        pqr.append([g() for g in own])
        gc.append(lat_gc())
    return np.array(raw), np.array(near), np.array(pqr), np.array(gc), fdm


def test_earth_relative_rates_are_derived_within_jsbsims_quaternion_drift(manoeuvre):
    raw, _, pqr, gc, _ = manoeuvre
    assert np.abs(pqr).max() > 0.05  # the inputs made it roll and pitch
    derived = fv.earth_rates_reference(raw[:, :layouts.N_RAW])
    assert np.abs(derived - pqr).max() <= RATE_BOUND
    # the compiled truth row derives the same rates (its velocity lever-arm term w_eb x l uses them)
    const = np.zeros(layouts.N_CONST)
    const[layouts.N_CONST - 1] = 1.0 / 120.0  # the step dt ends the constants
    for k in range(0, len(raw), 97):
        out = np.full(36, np.nan)
        _, p, q, _ = fk._imu_point(raw[k], const, np.array([0.0]), np.array([0.0]), 0.0, out)
        assert (p, q) == pytest.approx(tuple(derived[k, :2]), rel=0, abs=1e-17)
    # the latitude matters: JSBSim's local frame is geodetic (with the geocentric one the rates miss by ~1e-7)
    wrong = raw[:, :layouts.N_RAW].copy()
    wrong[:, 0] = gc
    assert np.abs(fv.earth_rates_reference(wrong) - pqr).max() > 1e-8


def test_loop_io_reads_the_fields_in_order_with_the_gear_stood_in_for(manoeuvre):
    raw, near, _, _, fdm = manoeuvre
    assert raw.shape == near.shape == (3000, layouts.N_RAW + len(layouts.GEAR_FIELDS))
    np.testing.assert_array_equal(raw[:, layouts.N_RAW:], np.broadcast_to(layouts.GEAR_AIRBORNE, (3000, 5)))
    np.testing.assert_array_equal(raw[:, :layouts.N_RAW], near[:, :layouts.N_RAW])
    io = fdm.loop_io(layouts.RAW_FIELDS, layouts.GEAR_FIELDS, layouts.GEAR_AIRBORNE)
    assert io.read_near() == tuple(fdm[name] for name in (*layouts.RAW_FIELDS, *layouts.GEAR_FIELDS))
    assert near[-1, layouts.N_RAW + 3] > 1000.0  # the gear's height above the ground, ft: the reads are real
    with pytest.raises(ValueError, match="one value per"):
        fdm.loop_io(layouts.RAW_FIELDS, layouts.GEAR_FIELDS, (0.0,))
