"""The compiled IMU error application (sensors/kernels/imu.py) against the numpy `Imu.apply_reference`: equal to
1e-12 relative for one run and a batch, with and without quantization; a run's bits independent of its batch. The
compiled Gauss-Markov recursion (sensors/kernels/noise.py) against scipy's lfilter, and the compiled radar altimeter
(sensors/kernels/radalt.py) against `RadarAltimeter.apply_reference`: bit for bit. The compiled baro
(sensors/kernels/baro.py) against `Baro.apply_reference`: to 1e-12 of the ISA scale T0 / L (4.4e-8 m), with and
without the static-system lag. The compiled pseudolites (sensors/kernels/pseudolite.py) against
`Pseudolite.apply_reference`: 1e-12 relative, validity identical."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from approachsim.sensors import atmosphere, base
from approachsim.sensors.baro import Baro
from approachsim.sensors.gnss.clock import ClockModel
from approachsim.sensors.gnss.receiver import draw_receiver_clock
from approachsim.sensors.imu import Imu
from approachsim.sensors.presets import PRESETS
from approachsim.sensors.pseudolite import Pseudolite
from approachsim.sensors.radalt import RadarAltimeter


def _close(a, b, what):
    scale = np.maximum(np.abs(b), np.max(np.abs(b)) * 1e-3 + 1e-300)
    rel = np.max(np.abs(a - b) / scale)
    assert rel <= 1e-12, f"{what}: relative difference {rel:.2e}"


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
        _close(a.dtheta_body, b.dtheta_body, "dtheta")
        _close(a.dv_body, b.dv_body, "dv")
        if quantized:  # the same grid values as the reference (a tie at half a step could round either way)
            assert np.mean(a.dtheta_body == b.dtheta_body) > 0.999
            assert np.mean(a.dv_body == b.dv_body) > 0.999
    # run 0 of the batch has run `one`'s generator: the same bits alone and in the batch
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
            np.testing.assert_array_equal(x, y, err_msg=f)
        assert a.valid.any() and not a.valid.all()


@pytest.mark.parametrize("lag_s", [0.0, 0.4])
@pytest.mark.parametrize("correction", [(0.0, 1.0), (1650.0, 0.9)])
def test_baro_kernel_equals_numpy_reference(descent, lag_s, correction):
    """|h - h_ref| <= 1e-12 T0 / L (the indication's own scale; near sea level it cancels to a few metres, so one
    rounding of the power differs by ~1e-11 m between libm and numpy); a run's bits independent of its batch; with
    and without a temperature correction (field H_f m, ratio c)."""
    baro = Baro(setting_pa=101000.0, scale_factor_sigma=1e-3, lag_s=lag_s, field_m=correction[0],
                temperature_ratio=correction[1])
    one = baro.draw(descent.t_s, np.random.default_rng(3))
    batch = baro.draw(descent.t_s, [np.random.default_rng(s) for s in (3, 4, 5)])
    tol_m = 1e-12 * atmosphere.T0_K / atmosphere.LAPSE_K_PER_M
    for e in (one, batch):
        a, b = baro.apply(descent, e), baro.apply_reference(descent, e)
        assert a.h_baro_m.shape == b.h_baro_m.shape
        assert np.max(np.abs(a.h_baro_m - b.h_baro_m)) <= tol_m
        for f in ("sigma_m", "valid", "fault", "t_s"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
    np.testing.assert_array_equal(baro.apply(descent, batch).h_baro_m[0], baro.apply(descent, one).h_baro_m)
    if lag_s > 0.0:  # the lag is in: a descent reads high
        lagged = baro.apply(descent, one.zeroed()).h_baro_m
        plain = Baro(setting_pa=101000.0).apply(descent, one.zeroed()).h_baro_m
        assert np.all(lagged[5:] > plain[5:])


def test_pseudolite_kernel_equals_numpy_reference(descent, runway):
    """Two unsynchronized units (one beyond a 9 km range for the first part of the approach, a 2 deg mask): every
    field to 1e-12 relative and the same validity, one run and a batch, with and without the receiver clock."""
    pl = Pseudolite(runway=runway, positions_rwy=((300.0, -150.0, 9.0), (-9000.0, 400.0, 5.0)), synchronized=False,
                    max_range_m=9000.0, mask_rad=math.radians(2.0))
    for seeds in ((3,), (3, 4, 5)):
        rngs = [np.random.default_rng(s) for s in seeds]
        e = pl.draw(descent.t_s, rngs if len(seeds) > 1 else rngs[0])
        clk = draw_receiver_clock(ClockModel(), descent.t_s, 1.0, [np.random.default_rng(10 + s) for s in seeds]
                                  if len(seeds) > 1 else np.random.default_rng(10))
        for c in (None, clk):
            a, b = pl.apply(descent, e, c), pl.apply_reference(descent, e, c)
            for f in ("pseudorange_m", "sigma_m", "elevation_rad", "clock_bias_m", "r_pl_ecef"):
                x, y = getattr(a, f), getattr(b, f)
                assert x.shape == y.shape, f
                assert np.array_equal(np.isfinite(x), np.isfinite(y)), f
                _close(np.nan_to_num(x), np.nan_to_num(y), f)
            np.testing.assert_array_equal(a.valid, b.valid)
            np.testing.assert_array_equal(a.fault, b.fault)
            assert a.valid.any() and not a.valid.all()
