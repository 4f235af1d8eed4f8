"""The envelope study: the approach flown across the aircraft's envelope (wind, turbulence, temperature, field
elevation, glidepath) and the flight technical error of each combination.

Used by the envelope acceptance test (tests/integration/test_flight_envelope.py) and by
tools/envelope_table.py, which writes docs/envelope.md and its figure. The design is fixed, not drawn: 28
cases, the 7 wind cases (headwind 0/10/20/25 kt, crosswind 15/25 kt from the left/right, tailwind 15 kt) x
the 2 turbulence levels, twice, with ISA deviation, field elevation and glidepath cycling through their
levels so that every level of every factor appears; a case whose planned sink rate exceeds the
stabilized-approach limit (flight.envelope) takes the next shallower glidepath and says so.

Per case, between 1000 and 200 ft above the threshold on the true IMU state (runway frame from ECEF):
vertical and lateral deviation RMS, CAS range against the target, the flight-path angle fitted to height
against along-track distance, and where 50 ft is reached against where the glidepath puts it.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from approachsim import units
from approachsim.config import ProfileError
from approachsim.flight.run import R_AIR, Approach
from approachsim.profile import parse_profile

WIND_CASES = (
    ("calm", 0.0, 0.0),
    ("headwind 10 kt", 10.0, 0.0),
    ("headwind 20 kt", 20.0, 0.0),
    ("headwind 25 kt", 25.0, 0.0),
    ("crosswind 15 kt", 15.0, -90.0),
    ("crosswind 25 kt", 25.0, 90.0),
    ("tailwind 15 kt", 15.0, 180.0),
)
"""(label, speed kt, wind direction relative to the runway heading, deg: 0 head, 180 tail, -90 from the left)."""
TURBULENCE = ("light", "moderate")
ISA_DEV_C = (-30.0, 0.0, 30.0)
ELEVATION_FT = (0.0, 5000.0, 8000.0)
GLIDEPATH_DEG = (2.5, 3.0, 3.5)
RHO0 = 1.225
"""ISA sea-level density, kg/m^3."""
START_NMI = 6.0
"""Start distance: 6 nmi (about 1900 ft above the threshold on 3 deg), a minute of flight before the 1000 ft gate."""


@dataclass(frozen=True)
class Case:
    """One envelope combination."""

    index: int
    wind: str
    wind_speed_kt: float
    wind_rel_deg: float
    turbulence: str
    isa_dev_c: float
    elevation_ft: float
    glidepath_deg: float
    note: str = ""


def cases() -> list[Case]:
    """The 28 envelope cases (module docstring)."""
    out = []
    for i in range(28):
        w = WIND_CASES[i % 7]
        turb = TURBULENCE[(i // 7) % 2]
        isa = ISA_DEV_C[i % 3]
        elev = ELEVATION_FT[(i // 3) % 3]
        gp_i = (i // 9 + i) % 3
        out.append(Case(i, w[0], w[1], w[2], turb, isa, elev, GLIDEPATH_DEG[gp_i]))
    return out


def profile_dict(base: dict, case: Case) -> dict:
    """The base profile dict (a parsed default.toml) changed to the case's runway and weather."""
    d = copy.deepcopy(base)
    hdg = float(d["runway"]["heading_true_deg"])
    d["runway"].update(elevation_ft=case.elevation_ft, glidepath_deg=case.glidepath_deg, start_distance_nmi=START_NMI)
    d["environment"].update(wind_speed_kt=case.wind_speed_kt, wind_from_deg=(hdg + case.wind_rel_deg) % 360.0,
                            turbulence=case.turbulence, isa_dev_C=case.isa_dev_c)
    d.pop("terrain", None)
    return d


def admissible(base: dict, case: Case, source: Path | None = None) -> Case:
    """The case, with the glidepath lowered one level at a time while the profile is outside the envelope's
    sink-rate limit (noted); ProfileError for any other envelope violation."""
    gp_levels = [g for g in GLIDEPATH_DEG if g <= case.glidepath_deg]
    for gp in reversed(gp_levels):
        c = Case(**{**case.__dict__, "glidepath_deg": gp,
                    "note": "" if gp == case.glidepath_deg else f"{case.glidepath_deg} deg needs > 1000 ft/min"})
        try:
            Approach(parse_profile(profile_dict(base, c), source=source))
            return c
        except ProfileError as e:
            if "ft/min" not in str(e):
                raise
    raise ProfileError(f"envelope case {case.index}: no glidepath keeps the sink rate inside the limit")


def measure(approach: Approach, seed: int, run: int = 0) -> dict:
    """Fly the approach once (truth navigation) and measure the flight technical error between 1000 and
    200 ft above the threshold (ft, kt, deg) and the 50 ft point."""
    res = approach.fly(seed=seed, run=run)
    prof = approach.profile
    rw = prof.runway
    tr = res.truth
    x, y, z = tr.r_rwy[:, 0], tr.r_rwy[:, 1], tr.r_rwy[:, 2]
    sel = (z <= 1000.0 * units.FT) & (z >= 200.0 * units.FT)
    out = {"termination": res.termination, "ok": res.ok}
    if not np.any(sel):
        return out
    d = tr.gs_dev_m  # true glidepath deviation from the straight cone (approachsim.glidepath)
    target = approach.aircraft.approach_speed_mps
    cas_err = tr.airspeed_mps[sel] - target
    # speed through the mean air mass (ground velocity - steady wind) as EAS (= CAS within 0.3 kt at M 0.25),
    # density from the recorded static pressure and temperature; 3 s trailing mean as the stabilized criterion
    env = prof.environment
    w = -env.wind_speed_mps * np.array([math.cos(env.wind_from_rad), math.sin(env.wind_from_rad), 0.0])
    tas_air = np.linalg.norm(tr.v_ned - w, axis=1)
    rho = tr.p_static_pa / (R_AIR * tr.t_air_k)
    eas = tas_air * np.sqrt(rho / RHO0)
    n = max(1, int(round(3.0 * prof.rates.imu_hz)))
    mean3 = np.convolve(eas, np.ones(n) / n, mode="full")[: eas.size]
    mean3[: n - 1] = np.nan
    air_err = mean3[sel] - target
    _, x_gpi, ca, cb, cc = rw.glidepath.constants()
    dx = x - x_gpi
    z_plane = z - (ca * dx * dx + cb * dx * y + cc * y * y)  # height above the GPI's horizontal plane
    slope = np.polyfit(x[sel], z_plane[sel], 1)[0]  # dz/dx = -tan(flight-path angle)
    out.update(
        vertical_rms_ft=float(np.sqrt(np.mean(d[sel] ** 2)) / units.FT),
        lateral_rms_ft=float(np.sqrt(np.mean(y[sel] ** 2)) / units.FT),
        vertical_max_ft=float(np.max(np.abs(d[sel])) / units.FT),
        lateral_max_ft=float(np.max(np.abs(y[sel])) / units.FT),
        cas_err_min_kt=float(cas_err.min() / units.KT),
        cas_err_max_kt=float(cas_err.max() / units.KT),
        airmass_err_min_kt=float(np.nanmin(air_err) / units.KT),
        airmass_err_max_kt=float(np.nanmax(air_err) / units.KT),
        path_deg=float(-math.degrees(math.atan(slope))),
        path_err_deg=float(-math.degrees(math.atan(slope)) - math.degrees(rw.glidepath_rad)),
    )
    h50 = 50.0 * units.FT
    below = np.nonzero(z <= h50)[0]
    if below.size and below[0] > 0:
        k = below[0]
        f = (z[k - 1] - h50) / (z[k - 1] - z[k])
        x50 = x[k - 1] + f * (x[k] - x[k - 1])
        x50_gp = (rw.tch_m - h50) / math.tan(rw.glidepath_rad)
        out["x50_err_ft"] = float((x50 - x50_gp) / units.FT)
    return out
