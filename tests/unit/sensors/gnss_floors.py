"""Floors of a GPS record computed twice (the compiled kernels against `apply_reference`), field by field, from the
sizes of what each field is computed from (tests/floors.py): the orbit's phase angles, the two ECEF positions a range
is the difference of, the slope of the elevation-dependent sigma.

    orbit:      u = u0 + u_ep + n t and lambda = Omega - (g_ep + w_E t), each a sum of up to 4 pi (the epoch phases
                are reduced mod 2 pi), 3 roundings: floor(3, 4 pi) rad each, a = 2.66e7 m times both, plus ~5
                roundings of a in the trig products: floor(6, 4 pi a) + floor(5, a) = 4.7e-7 m.
    range:      |r_sv - r| of 2.7e7 m and 6.4e6 m operands: floor(1, |r_sv|, |r|) + floor(4, range) + the orbit's.
    los:        a unit-vector component: the range's floor over the range, plus ~8 roundings of 1 (norm, division,
                the NED rotation from the receiver's geodetic latitude): ~2.5e-14.
    elevation:  asin of a los component: los / cos(el), at most sqrt(2 los) at the zenith; azimuth: los / cos(el).
    pdop:       sqrt(trace((G'G)^-1)[:3]); a perturbation dA of A = G'G moves Q = A^-1 by Q dA Q, |Q| <= gdop^2 <=
                2 pdop^2 (tdop < pdop for a ground user's sky), A's entries sums of up to 24 products of los
                components, |dA| <= 48 (los + floor(16, 1)): dpdop = d(pdop^2) / (2 pdop) <= 96 pdop^3 (los + 16 eps).
    sigma:      the model's slope in elevation (finite difference of the budget) times the elevation floor, plus
                floor(24, sigma) (an RSS of ~5 mapped terms).
    pseudorange, carrier: the range's floor plus floor(12, |value|, |clock bias|) (the error terms summed onto it);
    rate:       |v_sv - v_rx| times the los floor, plus the velocity's own (the orbit's relative floor of |v_sv|),
                plus floor(12, |v_sv|, |v_rx|, |rate|, |drift|).
"""

from __future__ import annotations

import math

import numpy as np
from floors import floor

from approachsim.geo import OMEGA_E
from approachsim.sensors.gnss.constellation import MU_GPS

PHASE_RAD = 4.0 * math.pi
"""Largest orbit phase angle a kernel and its oracle round: u0 + (n t_ep mod 2 pi) + n t, under 4 pi (+ n t)."""


def orbit_floor(a_m: float) -> float:
    """Floor of a satellite position component, m (module docstring)."""
    return float(floor(6, PHASE_RAD * a_m) + floor(5, a_m))


def v_sv_max(a_m: float) -> float:
    """Largest satellite speed relative to the rotating Earth, m/s: orbital speed plus w_E a."""
    return math.sqrt(MU_GPS / a_m) + OMEGA_E * a_m


def record_floors(rx, truth, rows, b) -> dict[str, np.ndarray]:
    """The floor of each float field of the GPS record `b` (the reference) at truth `rows` of receiver `rx`."""
    a_m = float(rx.constellation.a_m)
    orb = orbit_floor(a_m)
    r_rx = truth.r_ecef[rows]  # (m, 3)
    d = b.r_sv_ecef - r_rx[:, None, :]
    rng = np.linalg.norm(d, axis=-1)  # (.., m, 24)
    rng_floor = orb + floor(1, np.linalg.norm(b.r_sv_ecef, axis=-1), np.linalg.norm(r_rx, axis=-1)[:, None]) \
        + floor(4, rng)
    los = rng_floor / rng + floor(8, 1.0)
    el = b.elevation_rad
    cos_el = np.cos(el)
    el_floor = los / np.maximum(cos_el, np.sqrt(los)) + floor(4, el)
    az_floor = los / np.maximum(cos_el, los) + floor(4, 2.0 * math.pi)
    geom = (None, None, None)
    if rx.budget.gbas is not None:
        geom = tuple(x[:, None] for x in rx.station_geometry(truth, rows))
    h = 1e-6
    slope = np.abs(rx.sigma_m(el + h, *geom) - rx.sigma_m(el - h, *geom)) / (2.0 * h)
    out = {
        "t_s": np.zeros(()),
        "r_sv_ecef": np.full((), orb),
        "elevation_rad": el_floor,
        "azimuth_rad": az_floor,
        "sigma_m": slope * el_floor + floor(24, b.sigma_m),
        "pdop": np.where(np.isfinite(b.pdop), 96.0 * b.pdop**3 * (los.max(axis=-1) + floor(16, 1.0)), 0.0),
        "clock_bias_m": np.zeros(()),  # the clock arrays passed through: bit-identical
        "clock_drift_mps": np.zeros(()),
        "epoch_offset_s": np.zeros(()),
    }
    cb = np.abs(b.clock_bias_m)[..., None]
    out["pseudorange_m"] = rng_floor + floor(12, b.pseudorange_m, cb)
    if b.carrier_phase_m is not None:
        out["carrier_phase_m"] = rng_floor + floor(12, b.carrier_phase_m, cb)
    if b.pseudorange_rate_mps is not None:
        v_sv = v_sv_max(a_m)
        v_rx = np.linalg.norm(truth.v_ned[rows], axis=-1)[:, None]
        out["pseudorange_rate_mps"] = ((v_sv + v_rx) * los + floor(6, PHASE_RAD * v_sv) + floor(8, v_sv)
                                       + floor(12, v_sv, v_rx, b.pseudorange_rate_mps,
                                               np.abs(b.clock_drift_mps)[..., None]))
    return out


def look_floors(r_rx, r_sv, rng, el) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Floors of (range, los, elevation, azimuth) from receivers r_rx (m, 3) to the same satellites r_sv (m, k, 3)."""
    rng_floor = floor(1, np.linalg.norm(r_sv, axis=-1), np.linalg.norm(r_rx, axis=-1)[:, None]) + floor(4, rng)
    los = rng_floor / rng + floor(8, 1.0)
    cos_el = np.cos(el)
    return (rng_floor, los[..., None], los / np.maximum(cos_el, np.sqrt(los)) + floor(4, el),
            los / np.maximum(cos_el, los) + floor(4, 2.0 * math.pi))


def assert_fields_within(a, b, floors: dict[str, np.ndarray]) -> None:
    """Every float array field of records a, b: finite at the same places and within its floor there (azimuths
    modulo 2 pi); fields without a floor bit for bit; other arrays equal."""
    from dataclasses import fields

    from floors import assert_within

    for f in fields(b):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(y, np.ndarray) and y.dtype.kind == "f":
            assert x.shape == y.shape, f.name
            fin = np.isfinite(y)
            assert np.array_equal(np.isfinite(x), fin), f.name
            if f.name not in floors:
                np.testing.assert_array_equal(x, y, err_msg=f"{f.name}: bit-identical (the same input passed through)")
                continue
            xf, yf = np.where(fin, x, 0.0), np.where(fin, y, 0.0)
            if f.name == "azimuth_rad":
                xf = yf + np.remainder(xf - yf + math.pi, 2.0 * math.pi) - math.pi
            assert_within(xf, yf, np.broadcast_to(floors[f.name], y.shape), f.name)
        elif isinstance(y, np.ndarray):  # masks, selections, labels, arc ids: integers and booleans, exactly
            assert x.shape == y.shape and x.dtype == y.dtype, f.name
            np.testing.assert_array_equal(x, y, err_msg=f.name)
        else:
            assert (x is None and y is None) or np.array_equal(x, y), f.name
