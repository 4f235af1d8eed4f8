"""The compiled GPS kernels (sensors/kernels/gnss.py) against their numpy oracles: the best-PDOP selection identical
on the default approach's skies over a sidereal day and on random geometries (fewer than four, exactly four and many
visible); orbits, look angles and whole records (every selection, Doppler, both multipath models, one sky / per-run
skies / one run) equal to 1e-12 relative with identical masks."""

from __future__ import annotations

import math
from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest

from approachsim import synthetic
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
from approachsim.sensors.kernels import gnss as gk
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"


def _close(a, b, what, rel=1e-12):
    """|a - b| <= rel max(|b|, 1e-3 max|b|) where b is finite; non-finite where b is."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape, what
    fin = np.isfinite(b)
    assert np.array_equal(np.isfinite(a), fin), what
    if not fin.any():
        return
    x, y = a[fin], b[fin]
    scale = np.maximum(np.abs(y), np.max(np.abs(y)) * 1e-3 + 1e-300)
    worst = np.max(np.abs(x - y) / scale)
    assert worst <= rel, f"{what}: relative difference {worst:.2e}"


@pytest.fixture(scope="module")
def approach():
    """The default profile's synthetic approach (its runway, 10 nmi, 1 Hz GNSS rows) and receiver."""
    p = load_profile(PROFILES / "default.toml")
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
    for s, o in enumerate(offs):
        cs = rx.geometry_constellation(o)
        _close(r[s], cs.positions_ecef(t), "positions")
        _close(v[s], cs.velocities_ecef(t), "velocities")
        ref = look_angles(r_rx, r[s])
        for name, x, y in zip(("range", "u", "el", "az"), (rng[s], u[s], el[s], az[s]), ref, strict=True):
            _close(x, y, name)
    # one sky's orbits do not depend on the others or on the times asked with them
    r1, _ = c.orbits(t[5:6], offs[1:2])
    np.testing.assert_array_equal(r1[0], r[1, 5:6])


def _same_record(a, b):
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(y, np.ndarray) and y.dtype.kind == "f":
            _close(x, y, f.name)
        elif isinstance(y, np.ndarray):
            assert x.shape == y.shape and x.dtype == y.dtype, f.name
            np.testing.assert_array_equal(x, y, err_msg=f.name)
        else:
            assert (x is None and y is None) or np.array_equal(x, y), f.name


@pytest.mark.parametrize("selection", ["best4", "best4-fixed", "all"])
@pytest.mark.parametrize("multipath", ["do253", "nrc1995"])
def test_apply_equals_the_numpy_reference(approach, selection, multipath):
    """Records of 8 runs with their own skies, of 3 runs on one sky, and of one run: every float field to 1e-12
    relative, visibility, selection and validity identical (Doppler on, the receiver clock in)."""
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
        _same_record(a, b)
        assert a.valid.any()
