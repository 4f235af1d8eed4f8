"""The compiled GPS kernels (core/sensors/gnss.py) against their numpy oracles: the best-PDOP selection identical
on the default approach's skies over a sidereal day and on random geometries (fewer than four, exactly four and many
visible); orbits, look angles and whole records (every selection, Doppler, both multipath models, one sky / per-run
skies / one run) equal to their rounding floors (gnss_floors.py: from the orbit's phase angles and the ECEF operands
of the ranges, not from the results' size) with identical masks."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from floors import assert_within, floor
from gnss_floors import PHASE_RAD, assert_fields_within, look_floors, orbit_floor, record_floors, v_sv_max

from approachsim import synthetic
from approachsim.core.sensors import gnss as gk
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.gnss.constellation import Constellation, look_angles
from approachsim.sensors.gnss.receiver import (
    SIDEREAL_DAY_S,
    best_pdop_four,
    best_pdop_four_reference,
    draw_epoch_offsets,
    draw_receiver_clock,
    make_budget,
)
from approachsim.sensors.suite import SensorSuite

pytestmark = pytest.mark.equality  # also run compiled for the generic CPU target (scripts/test.sh)

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


@pytest.fixture(scope="module")
def approach():
    """The default profile's synthetic approach (its runway, 10 nmi, 1 Hz GNSS rows) and receiver."""
    p = load_profile(PY_DEFAULT)
    truth = synthetic.profile_descent(p, rate_hz=10.0)
    return truth, SensorSuite.from_profile(p).sensors["gnss"]


def test_best_four_equals_numpy_on_the_default_approach_over_a_day(approach):
    """60 skies spread over a sidereal day, every 1 Hz epoch of the approach (~16,000 epochs, 7-11 satellites in
    view): the compiled selection picks exactly numpy's combination at every epoch."""
    truth, rx = approach
    rows = np.arange(0, len(truth), 10)
    offs = np.linspace(0.0, SIDEREAL_DAY_S, 60, endpoint=False) + 17.0
    n_epochs = 0
    for o in offs:
        const = rx.geometry_constellation(o)
        _, u, el, _ = look_angles(truth.r_ecef[rows], const.positions_ecef(truth.t_s[rows]))
        vis = el >= rx.mask_rad
        np.testing.assert_array_equal(best_pdop_four(u, vis), best_pdop_four_reference(u, vis), err_msg=f"{o}")
        n_epochs += len(rows)
        assert vis.sum(axis=1).min() >= 5  # a real choice at every epoch
    assert n_epochs > 15000


@pytest.mark.parametrize("n_visible", [0, 1, 3, 4, 5, 6, 9, 13])
def test_best_four_equals_numpy_on_random_geometries(n_visible):
    """Random lines of sight (uniform on the sphere and a low-elevation cluster), n visible of 14 channels."""
    rng = np.random.default_rng(100 + n_visible)
    u = rng.standard_normal((400, 14, 3))
    u[200:, :, 2] = 0.2 * np.abs(u[200:, :, 2])  # near-coplanar skies: ill-conditioned combinations
    u /= np.linalg.norm(u, axis=-1, keepdims=True)
    vis = np.zeros((400, 14), dtype=bool)
    for i in range(400):
        vis[i, rng.choice(14, n_visible, replace=False)] = True
    sel = best_pdop_four(u, vis)
    np.testing.assert_array_equal(sel, best_pdop_four_reference(u, vis))
    assert np.all(sel.sum(axis=1) == min(n_visible, 4)) and not np.any(sel & ~vis)


def test_best_four_pdop_formula_equals_the_normal_equations():
    """The kernel's cross-product PDOP of four lines of sight equals sqrt(trace(inv(G'G))[:3]) (and `pdop`)."""
    rng = np.random.default_rng(7)
    for _ in range(50):
        u = rng.standard_normal((4, 3))
        u /= np.linalg.norm(u, axis=-1, keepdims=True)
        g = np.concatenate([-u, np.ones((4, 1))], axis=1)
        q = np.linalg.inv(g.T @ g)
        expect = math.sqrt(q[0, 0] + q[1, 1] + q[2, 2])
        assert gk.pdop(u, np.ones(4, dtype=bool)) == pytest.approx(expect, rel=1e-10)
        # pdop of 4 lines of sight two ways (cross products vs an inverse): rel 1e-10 = 4.5e5 eps, above the floor
        # 96 pdop^2 16 eps (gnss_floors.py) for the pdop < 30 of these draws; a near-singular draw would need more
        # a fifth channel next to channel 0: a set with both is near-degenerate (PDOP ~1e9) and never chosen
        u5 = np.concatenate([u, u[:1] * (1.0 - 1e-9) + 1e-9 * u[1:2]])
        u5 /= np.linalg.norm(u5, axis=-1, keepdims=True)
        sel = best_pdop_four(u5[None], np.ones((1, 5), dtype=bool))[0]
        assert sel.sum() == 4 and not (sel[0] and sel[4])
    assert gk.pdop(np.eye(3), np.ones(3, dtype=bool)) == math.inf


def test_orbits_and_look_angles_equal_numpy(approach):
    truth, rx = approach
    c: Constellation = rx.constellation
    t = truth.t_s[::10]
    offs = np.array([0.0, 3600.0 * 7.3, 80000.0])
    r, v = c.orbits(t, offs, with_velocity=True)
    r_rx = truth.r_ecef[::10]
    rng, u, el, az = gk.look_angles(np.ascontiguousarray(r_rx), r)
    a_m = float(c.a_m)
    v_max = v_sv_max(a_m)
    for s, o in enumerate(offs):
        cs = rx.geometry_constellation(o)
        # positions through phase angles up to 4 pi: floor(6, 4 pi a) + floor(5, a) = 4.7e-7 m (gnss_floors.py)
        assert_within(r[s], cs.positions_ecef(t), orbit_floor(a_m), "positions")
        assert_within(v[s], cs.velocities_ecef(t), floor(6, PHASE_RAD * v_max) + floor(8, v_max), "velocities")
        ref = look_angles(r_rx, r[s])
        fl = look_floors(r_rx, r[s], ref[0], ref[2])  # from the same satellite positions: the ECEF difference's floor
        for name, x, y, f in zip(("range", "u", "el", "az"), (rng[s], u[s], el[s], az[s]), ref, fl, strict=True):
            if name == "az":
                x = y + np.remainder(x - y + math.pi, 2.0 * math.pi) - math.pi
            assert_within(x, y, f, name)
    # bit-identical: same code path (one sky's orbits do not depend on the others or on the times asked with them)
    r1, _ = c.orbits(t[5:6], offs[1:2])
    np.testing.assert_array_equal(r1[0], r[1, 5:6])


@pytest.mark.parametrize("selection", ["best4", "best4-fixed", "all"])
@pytest.mark.parametrize("multipath", ["do253", "nrc1995"])
def test_apply_equals_the_numpy_reference(approach, selection, multipath):
    """Records of 8 runs with their own skies, of 3 runs on one sky, and of one run: every float field to its floor
    (gnss_floors.py), visibility, selection and validity identical (Doppler on, the receiver clock in)."""
    truth, rx0 = approach
    rx = replace(rx0, selection=selection, doppler=True, budget=make_budget("P(Y)", multipath, "current"))
    runs = list(range(8))
    e = rx.draw(truth.t_s, [stream(4, r, "gnss") for r in runs])
    off = draw_epoch_offsets(SIDEREAL_DAY_S, [stream(4, r, "gnss_epoch") for r in runs])
    clock = draw_receiver_clock(rx.clock, truth.t_s, rx.rate_hz, [stream(4, r, "receiver_clock") for r in runs])
    per_run = replace(e, constants={**e.constants, "epoch_offset_s": off})
    one_sky = e.take(slice(None))
    single = rx.draw(truth.t_s, stream(4, 3, "gnss"))
    single = replace(single, constants={**single.constants, "epoch_offset_s": np.array(off[3])})
    clock1 = draw_receiver_clock(rx.clock, truth.t_s, rx.rate_hz, stream(4, 3, "receiver_clock"))
    for errs, clk in ((per_run, clock), (replace(one_sky, series={k: v[:3] for k, v in one_sky.series.items()}),
                                         None), (single, clock1)):
        a, b = rx.apply(truth, errs, clk), rx.apply_reference(truth, errs, clk)
        assert_fields_within(a, b, record_floors(rx, truth, errs.rows, b))
        assert a.valid.any()
