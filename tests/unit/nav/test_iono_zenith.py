"""The zenith states of a GNSS service's filter (nav/errormodel.py, nav/noise.py, sensors/gnss/service.py): the
ionospheric field giz (common part, east and north planar gradient per d_5) present exactly for SBAS L1 and
stand-alone L1 C/A with the nominal filter model, the tropospheric residual gtz for every service under it; their
code-row entries are -F_pp(el) (1, (d / d_5) sin az, (d / d_5) cos az) and -M(el) (DO-229's 350 km obliquity and
tropospheric mapping, computed here from the elevation and azimuth the test derives itself) in the numpy row and the
compiled one; their variances and the channel states' sum to the truth's per channel; their realized values and the
channels' are the truth's split (the converged start conditions on them)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from approachsim import geo
from approachsim.core.nav import errormodel as ek
from approachsim.core.nav import measurements as mk
from approachsim.core.sensors import gnss_errors as ge
from approachsim.nav import errormodel as em
from approachsim.nav import measurements as meas
from approachsim.nav.noise import NoiseModel
from approachsim.nav.system import layout_for
from approachsim.profile import load_profile
from approachsim.sensors.gnss.receiver import make_budget
from approachsim.sensors.gnss.service import IONO_FIELD_WEIGHTS, ServiceModel

PROFILES = Path(__file__).resolve().parents[3] / "profiles"


def _f_pp(el_rad: float) -> float:
    """DO-229 A.4.4.10.4 obliquity, written out here: 1 / sqrt(1 - (R_e cos el / (R_e + h_I))^2), h_I = 350 km
    (R_e the WGS-84 semi-major axis, as the project's formula)."""
    x = geo.A_WGS84 * math.cos(el_rad) / (geo.A_WGS84 + 350e3)
    return 1.0 / math.sqrt(1.0 - x * x)


def _pierce(el_rad: float) -> float:
    """DO-229 A.4.4.10.1: the Earth-central angle pi/2 - el - asin(R_e cos el / (R_e + h_I)) times R_e, m."""
    return geo.A_WGS84 * (0.5 * math.pi - el_rad - math.asin(geo.A_WGS84 * math.cos(el_rad) / (geo.A_WGS84 + 350e3)))


def _m(el_rad: float) -> float:
    """DO-229 A.4.2.4 tropospheric mapping 1.001 / sqrt(0.002001 + sin^2 el)."""
    return 1.001 / math.sqrt(0.002001 + math.sin(el_rad) ** 2)


def _iono_row(el_rad: float, az_rad: float) -> np.ndarray:
    g = _f_pp(el_rad) * _pierce(el_rad) / _pierce(math.radians(5.0))
    return np.array([_f_pp(el_rad), g * math.sin(az_rad), g * math.cos(az_rad)])


@pytest.mark.parametrize(("profile", "iono", "tropo"), [
    ("sbas-lpv200", True, True), ("default", True, True), ("dfmc-sbas", False, True), ("gray-maybeck", False, False),
    ("gbas-cat3-candidate", False, False)])
def test_layout_has_the_states_exactly_where_the_truth_has_the_fields(profile, iono, tropo):
    prof = load_profile(PROFILES / f"{profile}.toml")
    lay = layout_for(prof.nav, prof.sensors)
    assert lay.has("giz") is iono and lay.has("gtz") is tropo
    assert bool(lay.packed[ek.L_GIZ] >= 0) is iono and bool(lay.packed[ek.L_GTZ] >= 0) is tropo
    nm = NoiseModel(prof.sensors, prof.nav, lay)
    P0 = nm.initial_covariance()
    F, Qc = em.dynamics_reference(lay, 0.6, 100.0, np.zeros(3), np.array([0, 0, -9.8]), np.eye(3), nm.noise(None),
                                  prof.nav.loop_gains() if lay.has("ac") else None)
    sv = prof.sensors.gnss.service
    if iono:  # P0 and the process noise at the service's field sigmas and the field's tau
        s0, sg, tau = sv.filter_iono_zenith()
        assert s0 > 0.0 and sg > 0.0 and tau == 1800.0
        k = np.arange(lay.index["giz"].start, lay.index["giz"].stop)
        np.testing.assert_array_equal(np.diag(P0)[k], [s0**2, sg**2, sg**2])
        np.testing.assert_array_equal(F[k, k], -1.0 / tau)
        np.testing.assert_allclose(Qc[k, k], 2.0 * np.array([s0, sg, sg]) ** 2 / tau, rtol=1e-15)
    if tropo:
        st, tau = sv.filter_tropo_zenith()
        assert st == pytest.approx(0.5 * 0.12, rel=1e-15) and tau == 3600.0
        assert P0[lay.i("gtz"), lay.i("gtz")] == st**2 and F[lay.i("gtz"), lay.i("gtz")] == -1.0 / tau


def test_service_rule():
    """The ionospheric field: single frequency and the nominal filter model (SBAS L1, and stand-alone L1 C/A whose
    Klobuchar residual the truth draws as the same field); the troposphere: the nominal model (one zenith residual
    in the truth of every service); neither with the broadcast model (every term per channel)."""
    for name, on in (("sbas-l1", True), ("l1ca", True), ("dfmc-sbas", False), ("dfmc", False), ("py-pps", False)):
        assert ServiceModel(name).iono_zenith_state is on and ServiceModel(name).tropo_zenith_state
        bc = ServiceModel(name, filter_model="broadcast")
        assert not bc.iono_zenith_state and not bc.tropo_zenith_state


@pytest.mark.parametrize("name", ["sbas-l1", "l1ca", "dfmc-sbas"])
def test_variance_split_sums_to_the_truths_total(name):
    """Per channel at 5-90 deg and every azimuth: row . diag(giz variances) . row + (the channel's iono)^2 = the
    truth's ionospheric variance (common, east and north gradient, local), and M^2 gtz^2 + (the channel's tropo)^2
    = the truth's tropospheric variance; the channel's slow sigma is sqrt(range^2 + iono^2 + tropo^2) with them; and
    the channels do not carry the whole fields (the states must exist)."""
    s = ServiceModel(name)
    el = np.radians(np.array([[5.0, 7.5, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0]]))
    az = np.radians(np.array([[0.0, 40.0, 95.0, 150.0, 200.0, 250.0, 300.0, 350.0]]))
    terms = np.array([ge.service_terms(float(e), s.filter_params()) for e in el[0]])  # the filter's channel terms
    sc = s.truth_scales(el, az)
    truth_iono = (sc["iono_common"] ** 2 + sc["iono_east"] ** 2 + sc["iono_north"] ** 2 + sc["iono_local"] ** 2)[0]
    if s.iono_zenith_state:
        s0, sg, _ = s.filter_iono_zenith()
        rows = np.array([_iono_row(float(e), float(a)) for e, a in zip(el[0], az[0], strict=True)])
        states = (rows**2 * np.array([s0, sg, sg]) ** 2).sum(axis=1)
        np.testing.assert_allclose(states + terms[:, 1] ** 2, truth_iono, rtol=1e-12)
        np.testing.assert_allclose(rows[:, 0] * s0, sc["iono_common"][0], rtol=1e-12)
        whole = s.filter_fractions()[1] * s.terms_m(el)[0, :, 1]
        assert np.all(terms[:, 1] < 0.3 * whole)  # only the local part (sqrt 0.05) left in the channels
        assert math.isclose(s0, s.filter_fractions()[1] * math.sqrt(IONO_FIELD_WEIGHTS[0]) * s.sigma_vertical_iono_m(),
                            rel_tol=1e-15)
    else:  # iono-free: the higher-order residual per channel, all of it in the channel
        np.testing.assert_allclose(terms[:, 1] ** 2, truth_iono, rtol=1e-12)
    st, _ = s.filter_tropo_zenith()
    m = np.array([_m(float(e)) for e in el[0]])
    np.testing.assert_allclose((st * m) ** 2 + terms[:, 2] ** 2, (sc["tropo"] ** 2 + sc["tropo_local"] ** 2)[0],
                               rtol=1e-12)
    assert not np.any(terms[:, 2])
    slow, _ = s.filter_channel_sigmas_m(el)
    np.testing.assert_allclose(slow[0], np.sqrt((terms[:, :3] ** 2).sum(axis=1)), rtol=1e-14)


def test_realized_states_are_the_truths_split():
    """The truth's channel slow error = the realized gse + the rows times the realized zenith states (receiver.
    channel_errors without the fields, iono_zenith_error and tropo_zenith_error their values)."""
    from approachsim.sensors.gnss.receiver import GnssReceiver

    s = ServiceModel("sbas-l1")
    rx = GnssReceiver(budget=make_budget("C/A", service=s))
    rng = np.random.default_rng(3)
    k = 6
    ser = {"range": rng.normal(size=(4, k)), "iono_local": rng.normal(size=(4, k)), "air": rng.normal(size=(4, k)),
           "iono_field": rng.normal(size=(4, 3)), "tropo": rng.normal(size=(4, 1)),
           "tropo_local": rng.normal(size=(4, k))}
    el = np.radians(np.linspace(6.0, 85.0, k))[None].repeat(4, 0)
    az = np.radians(np.linspace(10.0, 330.0, k))[None].repeat(4, 0)
    slow, _ = rx.channel_errors(ser, el, az_rad=az)
    giz, gtz = rx.iono_zenith_error(ser), rx.tropo_zenith_error(ser)
    assert giz.shape == (4, 3) and gtz.shape == (4,)
    r, io, tr, _ = s.truth_errors(ser, el, az)
    rows = np.array([[_iono_row(float(e), float(a)) for e, a in zip(el[i], az[i], strict=True)] for i in range(4)])
    m = np.vectorize(_m)(el)
    np.testing.assert_allclose(slow + np.einsum("nkj,nj->nk", rows, giz) + m * gtz[:, None], r + io + tr,
                               rtol=1e-11, atol=1e-13)


def test_code_row_entries():
    """A satellite's code row holds -F_pp(el) (1, (d / d_5) sin az, (d / d_5) cos az) at giz and -M(el) at gtz, el and
    az of the satellite seen from the corrected position (written out here from its NED direction), in the numpy row
    and the compiled one, and the innovation is linear in them with those coefficients; a pseudolite's row and a
    layout without the states have none."""
    lay = em.StateLayout(clock=True, n_sv=4, n_pl=1, iono_zenith=True, tropo_zenith=True)
    rng = np.random.default_rng(7)
    h = np.empty(lay.n)
    gi, gt = lay.index["giz"], lay.i("gtz")
    for _ in range(30):
        lat, lon, hh = rng.uniform(-1.2, 1.2), rng.uniform(-3.0, 3.0), rng.uniform(0.0, 3000.0)
        r_ins, c_en = geo.geodetic_to_ecef(lat, lon, hh), geo.c_ecef_to_ned(lat, lon)
        el0, az0 = rng.uniform(math.radians(3.0), math.radians(89.0)), rng.uniform(0.0, 2.0 * math.pi)
        to_sat = np.array([math.cos(el0) * math.cos(az0), math.cos(el0) * math.sin(az0), -math.sin(el0)])
        r_sv = r_ins + 2.2e7 * (c_en.T @ to_sat)
        x = rng.normal(size=lay.n) * 0.3
        x[lay.index["dp"]] = rng.normal(0.0, 5.0, 3)
        u = c_en @ (r_sv - (r_ins - c_en.T @ x[lay.index["dp"]]))  # from the corrected position
        el, az = math.asin(-u[2] / np.linalg.norm(u)), math.atan2(u[1], u[0])
        want = np.concatenate([-_iono_row(el, az), [-_m(el)]])
        rho = float(np.linalg.norm(r_ins - r_sv))
        m = meas.pseudorange(lay, x, r_ins, c_en, r_sv, rho, 1.0, 0.0, "r", sv=2)
        nu, _ = mk.pseudorange(lay.packed, x, r_ins, c_en, r_sv, rho, 1.0, 2, -1, h)
        for row in (m.h, h):
            np.testing.assert_allclose(row[gi], want[:3], rtol=1e-9, atol=1e-12)
            assert row[gt] == pytest.approx(want[3], rel=1e-9)
        dx = np.zeros(lay.n)
        dx[gi], dx[gt] = [0.5, -0.3, 0.2], 0.1
        nu2, _ = mk.pseudorange(lay.packed, x + dx, r_ins, c_en, r_sv, rho, 1.0, 2, -1, h)
        assert nu2 - nu == pytest.approx(-(want @ np.array([0.5, -0.3, 0.2, 0.1])), rel=1e-6, abs=1e-8)
        pl = meas.pseudorange(lay, x, r_ins, c_en, r_ins + 500.0 * (c_en.T @ to_sat), 500.0, 1.0, 0.0, "p", pl=0)
        assert not np.any(pl.h[gi]) and pl.h[gt] == 0.0
    plain = em.StateLayout(clock=True, n_sv=4)
    assert not plain.has("giz") and plain.packed[ek.L_GIZ] == -1 and plain.packed[ek.L_GTZ] == -1
    with pytest.raises(ValueError, match="zenith state"):
        em.StateLayout(clock=True, iono_zenith=True)
