"""The nominal 24-slot GPS constellation (SPS PS 2001 Table 3-1; standards.md 2.1) as circular Kepler orbits.

Slots are (RAAN, argument of latitude) at the reference epoch 1993-07-01 00:00 UTC, in an inertial frame whose
x axis was at Greenwich hour angle 18h 36m 14.4s at that epoch. Orbit: MAAST's MOPS almanac (almmops.txt):
e = 0, i = 55 deg, sqrt(A) = 5153.620087 m^0.5 (a = 26,559,800 m), no nodal regression; mu = 3.986005e14
m^3/s^2 (IS-GPS-200). A circular Kepler orbit advances its argument of latitude at the mean motion
n = sqrt(mu / a^3); ECEF follows by rotating the inertial frame by the Greenwich hour angle, which advances
at OMEGA_E. The simulation epoch (UTC) sets the time since the reference epoch at t = 0 of the run.
This is the nominal geometry for DOP and availability, not a real almanac of any date.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import UTC, datetime

import numpy as np

from approachsim import geo
from approachsim.core.sensors import gnss as gk

Array = np.ndarray

MU_GPS = 3.986005e14
"""Earth gravitational constant for GPS orbits (IS-GPS-200), m^3/s^2."""
A_NOMINAL_M = 5153.620087**2
"""Semi-major axis of the MOPS almanac, m (26,559,800 m)."""
INCLINATION_RAD = math.radians(55.0)
"""Nominal inclination."""
REFERENCE_EPOCH = datetime(1993, 7, 1, 0, 0, 0, tzinfo=UTC)
"""Epoch of SPS PS Table 3-1."""
GHA_AT_REFERENCE_RAD = math.radians((18.0 + 36.0 / 60.0 + 14.4 / 3600.0) * 15.0)
"""Greenwich hour angle of the inertial x axis at the reference epoch (18h 36m 14.4s)."""

SLOTS: tuple[tuple[str, float, float, int], ...] = (
    ("A1", 272.847, 268.126, 1), ("A2", 272.847, 161.786, 2), ("A3", 272.847, 11.676, 3),
    ("A4", 272.847, 41.806, 4), ("B1", 332.847, 80.956, 5), ("B2", 332.847, 173.336, 6),
    ("B3", 332.847, 309.976, 7), ("B4", 332.847, 204.376, 8), ("C1", 32.847, 111.876, 9),
    ("C2", 32.847, 11.796, 10), ("C3", 32.847, 339.666, 11), ("C4", 32.847, 241.556, 12),
    ("D1", 92.847, 135.226, 13), ("D2", 92.847, 265.446, 14), ("D3", 92.847, 35.156, 15),
    ("D4", 92.847, 167.356, 16), ("E1", 152.847, 197.046, 17), ("E2", 152.847, 302.596, 18),
    ("E3", 152.847, 66.066, 20), ("E4", 152.847, 333.686, 19), ("F1", 212.847, 238.886, 21),
    ("F2", 212.847, 345.226, 22), ("F3", 212.847, 105.206, 23), ("F4", 212.847, 135.346, 24),
)
"""(slot, RAAN deg, argument of latitude deg, PRN) at the reference epoch: SPS PS 2001 Table 3-1, MAAST PRNs."""


def parse_epoch(text: str) -> datetime:
    """An ISO-8601 UTC time ('2026-06-21T12:00:00Z') as an aware datetime; ValueError names the format."""
    try:
        dt = datetime.fromisoformat(text.replace("Z", "+00:00"))
    except ValueError:
        raise ValueError(f"must be an ISO-8601 UTC time such as 2026-06-21T12:00:00Z, got {text!r}") from None
    return dt.replace(tzinfo=UTC) if dt.tzinfo is None else dt.astimezone(UTC)


@dataclass(frozen=True)
class Constellation:
    """Circular-orbit constellation; epoch_s = seconds from REFERENCE_EPOCH to t = 0 of the run."""

    epoch_s: float
    raan_rad: Array
    u0_rad: Array
    prn: Array
    a_m: float = A_NOMINAL_M
    inclination_rad: float = INCLINATION_RAD

    @classmethod
    def nominal(cls, epoch_utc: datetime | str = "2026-01-01T12:00:00Z") -> Constellation:
        """The 24 nominal slots at the given simulation epoch (UTC)."""
        ep = parse_epoch(epoch_utc) if isinstance(epoch_utc, str) else epoch_utc
        return cls(
            epoch_s=(ep - REFERENCE_EPOCH).total_seconds(),
            raan_rad=np.radians([s[1] for s in SLOTS]),
            u0_rad=np.radians([s[2] for s in SLOTS]),
            prn=np.array([s[3] for s in SLOTS]),
        )

    def epoch_phases(self, offset_s: float = 0.0) -> tuple[float, float, float]:
        """Mean motion n (rad/s) and, offset_s (s) after the epoch, the argument-of-latitude advance n t_ep and the
        Greenwich hour angle of the inertial x axis, both reduced mod 2 pi (rad), t_ep = epoch_s + offset_s."""
        n_mot = math.sqrt(MU_GPS / self.a_m**3)
        ep = self.epoch_s + float(offset_s)
        # phases reduced mod 2 pi at the epoch first, so decades of propagation keep full precision
        u_ep = math.fmod(n_mot * ep, 2.0 * math.pi)
        g_ep = math.fmod(GHA_AT_REFERENCE_RAD + geo.OMEGA_E * ep, 2.0 * math.pi)
        return n_mot, u_ep, g_ep

    def orbits(self, t_s: Array, offsets_s: Array, with_velocity: bool = False) -> tuple[Array, Array | None]:
        """Positions (S, m, 24, 3), ECEF, m, at run times t_s (m,) of the S skies offsets_s (S,) s after the epoch,
        and with_velocity their velocities relative to the rotating Earth (same shape), m/s (else None).

        The compiled kernel (core/sensors/gnss.py sv_orbits) of positions_ecef / velocities_ecef (the numpy
        oracles, equal to 1e-12 relative): one sky's values do not depend on the others or on the times asked."""
        t = np.ascontiguousarray(t_s, dtype=float)
        offs = np.atleast_1d(np.asarray(offsets_s, dtype=float))
        ph = np.array([self.epoch_phases(o) for o in offs]).reshape(-1, 3)
        n_mot = math.sqrt(MU_GPS / self.a_m**3)
        r = np.empty((offs.shape[0], t.shape[0], self.prn.shape[0], 3))
        v = np.empty(r.shape if with_velocity else (0, 0, 0, 3))
        gk.sv_orbits(np.ascontiguousarray(self.u0_rad, dtype=float), np.ascontiguousarray(self.raan_rad, dtype=float),
                     float(self.a_m), math.cos(self.inclination_rad), math.sin(self.inclination_rad), n_mot,
                     np.ascontiguousarray(ph[:, 1]), np.ascontiguousarray(ph[:, 2]), t, with_velocity, r, v)
        return r, (v if with_velocity else None)

    def _angles(self, t_s: Array) -> tuple[Array, Array, float]:
        t = np.asarray(t_s, dtype=float)
        n_mot, u_ep, g_ep = self.epoch_phases()
        u = self.u0_rad[None, :] + u_ep + n_mot * t[:, None]
        lam = self.raan_rad[None, :] - (g_ep + geo.OMEGA_E * t[:, None])  # node longitude in ECEF
        return u, lam, n_mot

    def velocities_ecef(self, t_s: Array) -> Array:
        """Satellite velocities relative to the rotating Earth (n, 24, 3), ECEF axes, m/s (d/dt of positions)."""
        u, lam, n_mot = self._angles(t_s)
        ci = math.cos(self.inclination_rad)
        si = math.sin(self.inclination_rad)
        cu, su = np.cos(u), np.sin(u)
        cl, sl = np.cos(lam), np.sin(lam)
        ld = -geo.OMEGA_E
        vx = self.a_m * (-su * n_mot * cl - cu * sl * ld - cu * n_mot * ci * sl - su * ci * cl * ld)
        vy = self.a_m * (-su * n_mot * sl + cu * cl * ld + cu * n_mot * ci * cl - su * ci * sl * ld)
        vz = self.a_m * (cu * n_mot * si)
        return np.stack([vx, vy, vz], axis=-1)

    def positions_ecef(self, t_s: Array) -> Array:
        """Satellite positions (n, 24, 3), ECEF, m, at run times t_s (n,)."""
        u, lam, _ = self._angles(t_s)
        ci = math.cos(self.inclination_rad)
        si = math.sin(self.inclination_rad)
        cu, su = np.cos(u), np.sin(u)
        cl, sl = np.cos(lam), np.sin(lam)
        x = self.a_m * (cu * cl - su * ci * sl)
        y = self.a_m * (cu * sl + su * ci * cl)
        z = self.a_m * (su * si)
        return np.stack([x, y, z], axis=-1)


def look_angles(r_rx_ecef: Array, r_sv_ecef: Array) -> tuple[Array, Array, Array, Array]:
    """Range (m), unit line of sight ECEF, elevation and azimuth (rad) from receivers (n, 3) to SVs (n, k, 3)."""
    d = r_sv_ecef - r_rx_ecef[:, None, :]
    rng = np.linalg.norm(d, axis=-1)
    u = d / rng[..., None]
    lat, lon, _ = geo.ecef_to_geodetic(r_rx_ecef)
    c = geo.c_ecef_to_ned(lat, lon)  # (n, 3, 3)
    u_ned = np.einsum("nij,nkj->nki", c, u)
    el = np.arcsin(np.clip(-u_ned[..., 2], -1.0, 1.0))
    az = np.mod(np.arctan2(u_ned[..., 1], u_ned[..., 0]), 2.0 * math.pi)
    return rng, u, el, az


def dops(u_los: Array, use: Array, c_ecef_to_ned: Array) -> tuple[Array, Array, Array, Array]:
    """GDOP, PDOP, HDOP, VDOP (n,) of the channels `use` (n, k) with ECEF lines of sight u_los (n, k, 3).

    Geometry matrix rows [-u, 1] (Kaplan eq. 7.46); Q = (G'G)^-1; the position block is rotated to local NED
    with c_ecef_to_ned (n, 3, 3) for HDOP and VDOP. inf where fewer than 4 channels are used.
    """
    n = u_los.shape[0]
    g = np.concatenate([-u_los, np.ones(u_los.shape[:-1] + (1,))], axis=-1) * use[..., None]
    a = np.einsum("nki,nkj->nij", g, g)
    enough = use.sum(axis=1) >= 4
    out = np.full((4, n), np.inf)
    if np.any(enough):
        q = np.linalg.inv(a[enough])
        c = c_ecef_to_ned[enough]
        q_ned = c @ q[:, :3, :3] @ np.swapaxes(c, -1, -2)
        out[0, enough] = np.sqrt(np.trace(q, axis1=1, axis2=2))
        out[1, enough] = np.sqrt(np.trace(q_ned, axis1=1, axis2=2))
        out[2, enough] = np.sqrt(q_ned[:, 0, 0] + q_ned[:, 1, 1])
        out[3, enough] = np.sqrt(q_ned[:, 2, 2])
    return out[0], out[1], out[2], out[3]


def dops_ned(el_rad: Array, az_rad: Array, use: Array) -> tuple[Array, Array, Array]:
    """PDOP, HDOP, VDOP (...,) of the channels `use` (..., k) from their elevations and azimuths (rad, local NED).

    Lines of sight u = (cos el cos az, cos el sin az, -sin el); geometry rows [-u, 1] (Kaplan eq. 7.46),
    Q = (G'G)^-1 in NED directly. inf where fewer than 4 channels are used.
    """
    el = np.nan_to_num(np.asarray(el_rad, dtype=float))
    az = np.nan_to_num(np.asarray(az_rad, dtype=float))
    u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=-1)
    g = np.concatenate([-u, np.ones(u.shape[:-1] + (1,))], axis=-1) * np.asarray(use)[..., None]
    a = np.einsum("...ki,...kj->...ij", g, g)
    shape = a.shape[:-2]
    a = a.reshape((-1, 4, 4))
    enough = (np.asarray(use).sum(axis=-1) >= 4).reshape(-1)
    out = np.full((3, a.shape[0]), np.inf)
    if np.any(enough):
        q = np.linalg.inv(a[enough])
        out[0, enough] = np.sqrt(q[:, 0, 0] + q[:, 1, 1] + q[:, 2, 2])
        out[1, enough] = np.sqrt(q[:, 0, 0] + q[:, 1, 1])
        out[2, enough] = np.sqrt(q[:, 2, 2])
    return out[0].reshape(shape), out[1].reshape(shape), out[2].reshape(shape)
