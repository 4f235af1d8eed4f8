"""The compiled IMU error application (core/sensors/imu.py) against the numpy `Imu.apply_reference`: equal to the
rounding floor of the error model's sum (tests/floors.py: k eps times the sizes of its terms) for one run and a batch,
with and without quantization (then equal, or one step apart where a tie rounded the other way); a run's bits
independent of its batch. The compiled Gauss-Markov recursion (core/sensors/noise.py) against scipy's lfilter, and
the compiled radar altimeter (core/sensors/radalt.py) against `RadarAltimeter.apply_reference`: bit for bit (the
same operations in the same order, a contract of the kernels). The compiled baro (core/sensors/baro.py) against
`Baro.apply_reference`: to 1e-12 of the ISA scale T0 / L (4.4e-8 m, far above its floor), with and without the
static-system lag. The compiled pseudolites (core/sensors/pseudolite.py) against `Pseudolite.apply_reference`:
ranges and elevations to the floor of a difference of two ECEF positions, validity identical."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from floors import assert_within, floor

from approachsim.sensors import atmosphere, base
from approachsim.sensors.baro import Baro
from approachsim.sensors.gnss.clock import ClockModel
from approachsim.sensors.gnss.receiver import draw_receiver_clock
from approachsim.sensors.imu import Imu, true_increments
from approachsim.sensors.presets import PRESETS
from approachsim.sensors.pseudolite import Pseudolite
from approachsim.sensors.radalt import RadarAltimeter

pytestmark = pytest.mark.equality  # also run compiled for the generic CPU target (scripts/test.sh)


def _imu_floor(descent, e):
    """The floor of the kernel against the oracle, (runs, m, 3) or (m, 3): out_r = d_r + sum_j M_rj d_j + (b0_r +
    b_r) dt + n_r is ~10 roundings on its longest path (a 3-term dot product, four sums, a product; the kernel may
    fuse some, numpy's einsum may sum in another order): floor(12, the terms' sizes)."""
    dth, dv, dt = true_increments(descent, e.rows)
    s, k = e.series, e.constants
    lead = (slice(None), None) if e.batched else (None,)
    out = []
    for d, m, b0, b, n in ((dth, k["gyro_m"], k["gyro_bias0"], s["gyro_bias"], s["gyro_noise"]),
                           (dv, k["accel_m"], k["accel_bias0"], s["accel_bias"], s["accel_noise"])):
        md = np.einsum("...ij,...j->...i", np.abs(m)[lead], np.abs(d))
        out.append(floor(12, d, md, np.abs(b0)[lead] * dt, np.abs(b) * dt, n))
    return out


def _same_grid(a, b, q, what):
    """Quantized: q rint(v / q) in both, so equal wherever v / q rounds to the same integer (one product of the same
    two doubles); one step q apart where v sat within the floor of a tie and rounded the other way (rare)."""
    d = np.abs(a - b)
    step = np.abs(d - q) <= floor(2, a, b)
    assert np.all((d == 0.0) | step), f"{what}: neither equal nor one step apart"
    assert step.mean() < 1e-3, f"{what}: {step.mean():.2e} of the values a step apart"


@pytest.mark.parametrize("grade", ["nav-2.0", "mems"])
@pytest.mark.parametrize("quantized", [False, True])
def test_imu_apply_kernel_equals_numpy_reference(descent, grade, quantized):
    g = PRESETS[grade]
    if quantized:
        g = replace(g, gyro_quant_rad=1e-7, accel_quant_mps=1e-4)
    imu = Imu(g)
    one = imu.draw(descent.t_s, np.random.default_rng(3))
    batch = imu.draw(descent.t_s, [np.random.default_rng(s) for s in (3, 4, 5)])
    assert batch.batched and not one.batched
    for e in (one, batch):
        a, b = imu.apply(descent, e), imu.apply_reference(descent, e)
        assert a.dtheta_body.shape == b.dtheta_body.shape
        if quantized:  # the same grid values as the reference (a tie at half a step could round either way)
            _same_grid(a.dtheta_body, b.dtheta_body, g.gyro_quant_rad, "dtheta")
            _same_grid(a.dv_body, b.dv_body, g.accel_quant_mps, "dv")
        else:
            f_th, f_v = _imu_floor(descent, e)
            assert_within(a.dtheta_body, b.dtheta_body, f_th, "dtheta")
            assert_within(a.dv_body, b.dv_body, f_v, "dv")
    # bit-identical: same code path (run 0 of the batch has run `one`'s generator; the kernel's loop over runs)
    np.testing.assert_array_equal(imu.apply(descent, batch).dv_body[0], imu.apply(descent, one).dv_body)


@pytest.mark.parametrize(("shape", "sigma", "tau_s"), [
    ((31300,), 1.0, 100.0),
    ((31300, 3), np.array([1e-6, 2e-6, 3e-6]), np.array([3600.0, 100.0, np.inf])),
    ((266, 24), 1.0, 1e-3),
    ((1, 24), 0.5, 10.0),
    ((266, 2, 3), np.array([1.0, 0.0, 2.0]), 60.0),
])
def test_gauss_markov_kernel_equals_lfilter_bit_for_bit(shape, sigma, tau_s):
    """The draws keep their bits: the kernel's recursion x_k = d_k + a x_{k-1} rounds as lfilter's does."""
    z = np.random.default_rng(len(shape) * 1000 + shape[0]).standard_normal(shape)
    a = base.gauss_markov(z, sigma, tau_s, 1.0 / 120.0)
    b = base.gauss_markov_reference(z, sigma, tau_s, 1.0 / 120.0)
    assert a.shape == b.shape == z.shape
    # bit-identical by contract: one multiply-add per step in the same order as lfilter (core/sensors/noise.py),
    # no reassociation; a draw's bits must not depend on the path
    np.testing.assert_array_equal(a, b)
    assert np.any(a != 0.0)
    # columns of a wider draw (the IMU's z[:, 3:6]): a strided view gives the same bits as a contiguous copy
    wide = np.random.default_rng(9).standard_normal((shape[0], 12))
    np.testing.assert_array_equal(base.gauss_markov(wide[:, 3:6], 2.0, 50.0, 0.1),
                                  base.gauss_markov_reference(np.ascontiguousarray(wide[:, 3:6]), 2.0, 50.0, 0.1))



def test_radalt_kernel_equals_numpy_reference_bit_for_bit(descent):
    """One run and a batch over the whole descent (above and below the maximum range: nan and invalid above)."""
    ra = RadarAltimeter(max_range_m=200.0)
    for rng in (np.random.default_rng(3), [np.random.default_rng(s) for s in (3, 4, 5)]):
        e = ra.draw(descent.t_s, rng)
        a, b = ra.apply(descent, e), ra.apply_reference(descent, e)
        for f in ("h_agl_m", "sigma_m", "valid", "fault"):
            x, y = getattr(a, f), getattr(b, f)
            assert x.shape == y.shape and x.dtype == y.dtype, f
            # bit-identical by contract: the kernel evaluates the reference's sums in its order (radalt.py kernel)
            np.testing.assert_array_equal(x, y, err_msg=f)
        assert a.valid.any() and not a.valid.all()


@pytest.mark.parametrize("lag_s", [0.0, 0.4])
@pytest.mark.parametrize("correction", [(0.0, 1.0), (1650.0, 1.0), (1650.0, 0.9)])
def test_baro_kernel_equals_numpy_reference(descent, lag_s, correction):
    """|h - h_ref| <= 1e-12 T0 / L (the indication's own scale; near sea level it cancels to a few metres, so one
    rounding of the power differs by ~1e-11 m between libm and numpy); a run's bits independent of its batch; with
    and without a temperature correction (field H_f m, ratio c), the scale factor on the height above H_f."""
    baro = Baro(setting_pa=101000.0, scale_factor_sigma=1e-3, lag_s=lag_s, field_m=correction[0],
                temperature_ratio=correction[1])
    one = baro.draw(descent.t_s, np.random.default_rng(3))
    batch = baro.draw(descent.t_s, [np.random.default_rng(s) for s in (3, 4, 5)])
    # the indication (T0 / L)(1 - x^e) takes ~4 roundings of T0 / L = 44.3 km, the lag's weighted sum, the correction
    # and h (1 + S) + B + v ~6 more: floor(20, T0 / L) = 2e-10 m; 1e-12 T0 / L = 4.4e-8 m is 220x that
    tol_m = 1e-12 * atmosphere.T0_K / atmosphere.LAPSE_K_PER_M
    for e in (one, batch):
        a, b = baro.apply(descent, e), baro.apply_reference(descent, e)
        assert a.h_baro_m.shape == b.h_baro_m.shape
        assert np.max(np.abs(a.h_baro_m - b.h_baro_m)) <= tol_m
        for f in ("sigma_m", "valid", "fault", "t_s"):  # bit-identical: the same constant / the same array
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
    # bit-identical: same code path (run 0 of a batch and the run alone, one kernel loop)
    np.testing.assert_array_equal(baro.apply(descent, batch).h_baro_m[0], baro.apply(descent, one).h_baro_m)
    if lag_s > 0.0:  # the lag is in: a descent reads high
        lagged = baro.apply(descent, one.zeroed()).h_baro_m
        plain = Baro(setting_pa=101000.0).apply(descent, one.zeroed()).h_baro_m
        assert np.all(lagged[5:] > plain[5:])


def test_pseudolite_kernel_equals_numpy_reference(descent, runway):
    """Two unsynchronized units (one beyond a 9 km range for the first part of the approach, a 2 deg mask): ranges
    and elevations to the floor of an ECEF difference, the rest bit for bit, the same validity, one run and a batch,
    with and without the receiver clock."""
    pl = Pseudolite(runway=runway, positions_rwy=((300.0, -150.0, 9.0), (-9000.0, 400.0, 5.0)), synchronized=False,
                    max_range_m=9000.0, mask_rad=math.radians(2.0))
    for seeds in ((3,), (3, 4, 5)):
        rngs = [np.random.default_rng(s) for s in seeds]
        e = pl.draw(descent.t_s, rngs if len(seeds) > 1 else rngs[0])
        clk = draw_receiver_clock(ClockModel(), descent.t_s, 1.0, [np.random.default_rng(10 + s) for s in seeds]
                                  if len(seeds) > 1 else np.random.default_rng(10))
        r_rx = np.linalg.norm(descent.r_ecef[e.rows], axis=-1)[:, None]  # (m, 1)
        r_pl = np.linalg.norm(pl.r_published_ecef, axis=-1)[None, :]  # (1, p)
        rng_pl = np.linalg.norm(pl.r_published_ecef[None] - descent.r_ecef[e.rows][:, None], axis=-1)
        for c in (None, clk):
            a, b = pl.apply(descent, e, c), pl.apply_reference(descent, e, c)
            for f in ("pseudorange_m", "sigma_m", "elevation_rad", "clock_bias_m", "r_pl_ecef"):
                x, y = getattr(a, f), getattr(b, f)
                assert x.shape == y.shape, f
                assert np.array_equal(np.isfinite(x), np.isfinite(y)), f
            # a range is a difference of two 6.4e6 m ECEF positions (the survey error added to one: 2 roundings of
            # |r|), then a norm, the tropo scale and four sums relative to the range and the clock bias: floor(3,
            # |r_PL|, |r|) + floor(12, |rho|, |b_rx|); ~3e-9 m against ranges of 0.3..20 km (1e-12 relative of a
            # 300 m range, 3e-10 m, was below one ulp of the positions it is formed from)
            cb = np.abs(np.asarray(b.clock_bias_m))[..., None]
            assert_within(a.pseudorange_m, b.pseudorange_m, floor(3, r_pl, r_rx) + floor(12, b.pseudorange_m, cb),
                          "pseudorange")
            # el = asin(up / |d|) of the same difference d: its floor over the range, plus asin's own roundings
            assert_within(a.elevation_rad, b.elevation_rad, floor(3, r_pl, r_rx) / rng_pl + floor(8, b.elevation_rad),
                          "elevation")
            for f in ("sigma_m", "clock_bias_m", "r_pl_ecef"):  # bit-identical: the same constant / input array
                np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
            np.testing.assert_array_equal(a.valid, b.valid)
            np.testing.assert_array_equal(a.fault, b.fault)
            assert a.valid.any() and not a.valid.all()
