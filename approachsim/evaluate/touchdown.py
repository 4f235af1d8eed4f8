"""Touchdown: where and how each landing run put its main gear down, and the campaign's dispersion against the
autoland touchdown criteria, with what N runs can and cannot show.

Per run (`touchdown_scalars`, SI, from the last Truth row of a landing run, the row at which the flight stage saw
a main gear on the ground): the main-gear contact points and their velocities from the IMU point's position,
velocity, attitude and body rate and the gear's lever arms l (body axes, from the IMU),

    r_gear = r_imu + C_rn C_nb l,        v_gear = v_imu + C_nb (w x l)                         (rigid body)

C_nb from the roll, pitch, true heading (ZYX), C_rn the runway axes (x along the landing direction, y right, z
up) at the threshold. Dropped, and below a millimetre on a 10 m lever arm here: the Earth-rate part of the
inertial rate w_ib (7e-5 rad/s) and the meridian convergence between the threshold and the aircraft (5e-5 rad
at 500 m). Quantities: the longitudinal touchdown point (mean x of the two main gears, m past the threshold), the
lateral position of the main-gear centre and of the outboard main gear (the one farther from the centreline), the
sink rate of the main gear that touched (positive down), bank, pitch, crab (heading minus runway heading) and the
main-gear slip angle (ground track of the gear minus heading), beside the IMU point's own x, y and sink.

Campaign (`touchdown_details`): per quantity mean, standard deviation, percentiles and a normality check, and per
criterion (CRITERIA: a limit and the probability per landing it may be exceeded with, each with its source and a
confidence mark as in the project's reference notes: V read in the source, S secondary, U not found):

* empirical: exceedances k of N runs, failed runs counted as exceedances of every criterion (a run that did not
  land on the runway is a failed landing, never dropped); one-sided Clopper-Pearson bounds. With no exceedance the
  upper bound is 1 - (1 - c)^(1/N): 3.0e6 clean runs show 1e-6 at 95 %, 50 runs show 0.058.
* normal tail extrapolation (the method of ESDU 91019 and of the Boeing 757/767 autoland certification by
  simulation, both [S]; what AC 120-28D itself allows was not found, [U]): a normal fitted to the completed
  landings, the limit at z = (L - mean) / sd standard deviations from the mean, the implied probability
  Phi(-z) against the required one (z_required = Phi^-1(1 - p): 4.75 for 1e-6), and its exact confidence bounds
  for normal data: T = sqrt(n) (L - mean) / sd is noncentral t with n - 1 degrees of freedom and noncentrality
  delta = sqrt(n) (L - mu) / sigma (the one-sided normal tolerance limit), so the delta with P(T >= t_obs) = 1 - c
  gives the upper bound Phi(-delta / sqrt(n)) of the exceedance probability, and P(T <= t_obs) = 1 - c the lower.
  Two-sided criteria (|y| > L) add the two tails, each bounded at confidence 1 - (1 - c) / 2 (Bonferroni).
  Shapiro-Wilk tests the fit; it sees the bulk only. N runs map the distribution out to about its 1/N quantile
  (z ~ 2.3 at N = 50); beyond that the probability is the normal model's, not the runs'. A heavier tail (turbulence
  outliers, a flare law's nonlinearity) would be invisible to both and make Phi(-z) optimistic
  (tests/unit/evaluate/test_touchdown.py measures it on Student-t data).
* outcome: `exceeds` when the empirical lower bound is above the required probability, or the normal one is and
  normality is not rejected; `within` when there is no exceedance, the normal upper bound is within it,
  normality is not rejected and at least stats.MIN_RUNS landings completed; `indeterminate` otherwise, with the
  landings that would likely decide it. The outboard gear is scored on two normals, the right gear's upper tail
  and the left gear's lower tail (the signed outboard position is bimodal by construction).
* verdict: the outcome as `meets` / `fails` / `indeterminate` only for a limit marked V; for any other limit the
  verdict is `unverified_limit` whatever the numbers say: an unverified criterion never meets.

Units: the per-run scalars are SI (runs.parquet); details.json gives every figure in the criterion's display unit
(ft, ft/s, deg), as the summary does for the decision heights.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy import stats as sps
from scipy.integrate import quad
from scipy.optimize import brentq

from approachsim import units
from approachsim.evaluate.stats import MIN_RUNS, smallest_n
from approachsim.evaluate.verdict import clopper_pearson
from approachsim.records import Truth

Array = np.ndarray

# --- per run -----------------------------------------------------------------------------------------------------

SCALARS = (
    "td_t_s", "td_x_m", "td_y_m", "td_left_gear_y_m", "td_right_gear_y_m", "td_outboard_gear_y_m", "td_sink_mps",
    "td_gear_height_m", "td_imu_x_m", "td_imu_y_m", "td_imu_sink_mps", "td_bank_rad", "td_pitch_rad", "td_crab_rad",
    "td_gear_slip_rad", "td_cas_mps", "td_contact_bank_rad", "td_contact_margin_rad",
)
"""The per-run touchdown scalars (runs.parquet columns of a landing campaign), SI."""


def c_nb_from_euler(euler_rad: Array) -> Array:
    """(3, 3) body -> NED rotation from roll, pitch, true heading (ZYX): C_nb = R_z(psi) R_y(theta) R_x(phi)."""
    phi, theta, psi = (float(a) for a in euler_rad)
    cf, sf, ct, st, cp, sp = math.cos(phi), math.sin(phi), math.cos(theta), math.sin(theta), math.cos(psi), \
        math.sin(psi)
    return np.array([
        [ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
        [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
        [-st, sf * ct, cf * ct],
    ])


def c_rwy_ned(heading_rad: float) -> Array:
    """(3, 3) NED -> runway axes (x along the landing direction, y right, z up) for the runway's true heading."""
    ch, sh = math.cos(heading_rad), math.sin(heading_rad)
    return np.array([[ch, sh, 0.0], [-sh, ch, 0.0], [0.0, 0.0, -1.0]])


def gear_state(r_rwy: Array, v_ned: Array, euler_rad: Array, w_body: Array, heading_rad: float,
               lever_body_m: Array) -> tuple[Array, Array]:
    """(positions, velocities), each (k, 3) in runway axes (m, m/s; z up), of k points at body-axis lever arms
    lever_body_m (k, 3) from the IMU (x forward, y right, z down, m), given the IMU's runway-frame position r_rwy,
    NED velocity v_ned, attitude and body rate w_body (rad/s): r = r_imu + C_rn C_nb l, v = v_imu + C_nb (w x l)."""
    l_b = np.atleast_2d(np.asarray(lever_body_m, dtype=float))
    c_nb = c_nb_from_euler(euler_rad)
    c_rn = c_rwy_ned(heading_rad)
    c_rb = c_rn @ c_nb
    pos = np.asarray(r_rwy, dtype=float)[None, :] + l_b @ c_rb.T
    v_ned_pts = np.asarray(v_ned, dtype=float)[None, :] + np.cross(np.asarray(w_body, dtype=float), l_b) @ c_nb.T
    return pos, v_ned_pts @ c_rn.T


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def contact_bank_rad(theta_rad: float, d_body_m: Array) -> Array:
    """Bank angle (rad) at which points touch the ground plane the main gear of their side stands on, at pitch
    theta, rolling towards them: d_body_m (k, 3) the points' offsets from that gear's contact point, body axes
    (x forward, y outboard, z down), m. The point's height above the ground is
        h(phi) = sin(theta) d_x - cos(theta) (sin(phi) |d_y| + cos(phi) d_z)
    (rows of C_nb with the heading dropped), zero where A sin(phi) + B cos(phi) = C, A = cos(theta) |d_y|,
    B = cos(theta) d_z, C = sin(theta) d_x: phi = asin(C / R) - atan2(B, A), R = hypot(A, B). At theta = 0 a point
    h_0 = -d_z above the ground and |d_y| outboard touches at atan(h_0 / |d_y|); a nose-up pitch raises a point
    ahead of the gear (the nacelle) and lowers one behind it (a swept wingtip)."""
    d = np.atleast_2d(np.asarray(d_body_m, dtype=float))
    ct, st = math.cos(theta_rad), math.sin(theta_rad)
    a, b, c = ct * np.abs(d[:, 1]), ct * d[:, 2], st * d[:, 0]
    r = np.hypot(a, b)
    return np.arcsin(np.clip(c / r, -1.0, 1.0)) - np.arctan2(b, a)


def contact_offsets_m(points_struct_m: Array, gear_struct_m: Array, compression_m: float) -> Array:
    """(k, 3) body-axis offsets (x forward, y right, z down), m, of right-wing points from the right main gear's
    contact point, both given in JSBSim's structural frame (x aft, y right, z up), with the gear strut compressed
    by compression_m (the body comes that much closer to the ground)."""
    p = np.atleast_2d(np.asarray(points_struct_m, dtype=float))
    g = np.asarray(gear_struct_m, dtype=float)
    return np.column_stack((-(p[:, 0] - g[0]), p[:, 1] - g[1], -(p[:, 2] - g[2]) + compression_m))


def touchdown_scalars(truth: Truth, main_gear_body_m: Array, contact_body_m: Array | None = None, *,
                      slope: float = 0.0) -> dict[str, float]:
    """The run's touchdown quantities (SCALARS, SI) from the last row of a landing run's truth (the touchdown row)
    and the left and right main-gear contact points relative to the IMU, (2, 3) body axes (x forward, y right,
    z down), m. contact_body_m: the right wing's ground-contact points' offsets from the right main gear
    (contact_offsets_m; the left wing's mirror them): the contact bank at the touchdown pitch on the low wing's
    side and the margin to it (nan without them). slope: the runway's longitudinal slope past the threshold (rise per
    metre, profile.Runway.slope): the sink rate is the gear's closing speed on the runway surface, -v_z + slope v_x,
    and the gear height is above that surface (z - slope x); the ground contact stays the level-runway bank (a 2 %
    slope tilts the runway by 1.1 deg in pitch, which contact_bank_rad's pitch would take up)."""
    k = len(truth) - 1
    heading = truth.runway.heading_rad
    pos, vel = gear_state(truth.r_rwy[k], truth.v_ned[k], truth.euler_rad[k], truth.w_ib_body[k], heading,
                          main_gear_body_m)
    first = int(np.argmin(pos[:, 2]))  # the lower main gear is the one that touched
    out_i = int(np.argmax(np.abs(pos[:, 1])))
    phi, theta, psi = (float(a) for a in truth.euler_rad[k])
    v_first_ned = vel[first] @ c_rwy_ned(heading)  # runway -> NED (orthogonal)
    track = math.atan2(v_first_ned[1], v_first_ned[0])
    return {
        "td_t_s": float(truth.t_s[k]),
        "td_x_m": float(np.mean(pos[:, 0])),
        "td_y_m": float(np.mean(pos[:, 1])),
        "td_left_gear_y_m": float(pos[0, 1]),
        "td_right_gear_y_m": float(pos[1, 1]),
        "td_outboard_gear_y_m": float(pos[out_i, 1]),
        "td_sink_mps": float(-vel[first, 2] + slope * vel[first, 0]) if slope else float(-vel[first, 2]),
        "td_gear_height_m": float(pos[first, 2] - slope * pos[first, 0]) if slope else float(pos[first, 2]),
        "td_imu_x_m": float(truth.r_rwy[k, 0]),
        "td_imu_y_m": float(truth.r_rwy[k, 1]),
        "td_imu_sink_mps": float(truth.v_ned[k, 2]),
        "td_bank_rad": phi,
        "td_pitch_rad": theta,
        "td_crab_rad": _wrap(psi - heading),
        "td_gear_slip_rad": _wrap(track - psi),
        "td_cas_mps": float(truth.airspeed_mps[k]),
        **_contact(theta, phi, contact_body_m),
    }


def _contact(theta: float, phi: float, contact_body_m: Array | None) -> dict[str, float]:
    """td_contact_bank_rad (the smallest bank at which a low-wing point touches, at pitch theta) and
    td_contact_margin_rad (that less |bank|; < 0: contact)."""
    if contact_body_m is None:
        return {"td_contact_bank_rad": math.nan, "td_contact_margin_rad": math.nan}
    limit = float(np.min(contact_bank_rad(theta, contact_body_m)))
    return {"td_contact_bank_rad": limit, "td_contact_margin_rad": limit - abs(phi)}


# --- criteria ----------------------------------------------------------------------------------------------------

SMAC = "ONERA SMAC toolbox, Civil Aircraft Landing Challenge benchmark (its Monte Carlo plotting script): "
"""Where the [S] limits come from: a research benchmark's own statement of the risks to demonstrate, not the AC."""

DISPLAY = {"ft": 1.0 / units.FT, "ft/s": 1.0 / units.FPS, "deg": 180.0 / math.pi}
"""Factor from SI to each display unit."""


@dataclass(frozen=True)
class Criterion:
    """A touchdown criterion: the per-run quantity must not pass `limit` (SI) with more than `probability` per
    landing. side: "below" (exceeded when x < limit), "above" (x > limit) or "abs_above" (|x| > limit)."""

    key: str
    quantity: str
    side: str
    limit: float
    unit: str
    """Display unit of details.json: "ft", "ft/s" or "deg"."""
    probability: float
    mark: str
    """V: read in the source named; S: secondary source only; U: not found (a candidate kept to be checked)."""
    source: str
    what: str
    lower_quantity: str | None = None
    """abs_above only: the quantity whose lower tail (x < -limit) counts, when it is not `quantity` (the outboard
    gear: the right gear's upper tail and the left gear's lower tail; their signed outboard value is bimodal)."""

    @property
    def verified(self) -> bool:
        """True when the limit and its probability were read in the standard itself (mark V)."""
        return self.mark == "V"

    def exceeded(self, x: Array, x_low: Array | None = None) -> Array:
        """Boolean array: which values pass the limit (nan: False); x_low: the lower-tail values of an abs_above
        criterion with a lower_quantity (default x)."""
        x = np.asarray(x, dtype=float)
        xl = x if x_low is None else np.asarray(x_low, dtype=float)
        with np.errstate(invalid="ignore"):
            if self.side == "below":
                return x < self.limit
            if self.side == "above":
                return x > self.limit
            return (x > self.limit) | (xl < -self.limit)


CRITERIA = (
    Criterion("short", "td_x_m", "below", 60.0, "ft", 1e-6, "S",
              SMAC + "p1 = prob(HTP60 < 0), the wheels below the runway 60 m past the threshold, average risk "
              "< 1e-6; ESDU 91019 (abstract) analyses touchdown 'short' at 200 ft. AC 120-28D's own figure: U",
              "main gear touches down less than 60 m (197 ft) past the threshold"),
    Criterion("long", "td_x_m", "above", 915.0, "ft", 1e-6, "S",
              SMAC + "p2 = prob(XTP > 915 m), average risk < 1e-6; ESDU 91019 (abstract): 'long' at 3000 ft. The "
              "2700 ft often quoted for AC 120-28D: U (not seen in any source)",
              "main gear touches down more than 915 m (3000 ft) past the threshold"),
    Criterion("lateral", "td_y_m", "abs_above", 15.0, "ft", 1e-6, "S",
              SMAC + "p4 = prob(|YTP| > 15 m), lateral deviation at the touchdown point, average risk < 1e-6 (the "
              "file does not say which point of the aircraft; applied here to the main-gear centre)",
              "main-gear centre more than 15 m (49 ft) from the centreline"),
    Criterion("outboard_gear", "td_right_gear_y_m", "abs_above", 70.0 * units.FT, "ft", 1e-6, "U",
              "candidate only: '70 ft' for the outboard gear (a 150 ft runway's edge less 5 ft) is commonly "
              "attributed to AC 120-28D but was not seen in any source (shared/reference/integrity-envelope.md "
              "sec. 4), nor its probability",
              "outboard main gear more than 70 ft from the centreline (unverified candidate): the right gear "
              "right of +70 ft or the left gear left of -70 ft",
              lower_quantity="td_left_gear_y_m"),
    Criterion("sink", "td_sink_mps", "above", 10.0 * units.FPS, "ft/s", 1e-6, "S",
              SMAC + "p3 = prob(VZTP > 10 ft/s), vertical speed at touchdown, average risk < 1e-6. The AC's "
              "structural-limit wording: U",
              "main-gear sink rate above 10 ft/s at touchdown"),
    Criterion("sink_limit_risk", "td_sink_mps", "above", 12.0 * units.FPS, "ft/s", 1e-5, "S",
              SMAC + "p7 = prob(VZTP > 12 ft/s), limit risk < 1e-5",
              "main-gear sink rate above 12 ft/s at touchdown (limit-risk figure)"),
    Criterion("bank", "td_bank_rad", "abs_above", math.radians(12.0), "deg", 1e-8, "S",
              SMAC + "p5 = prob(|PHI| > 12 deg), roll angle at touchdown, average risk < 1e-8",
              "bank angle above 12 deg at touchdown"),
    Criterion("ground_contact", "td_contact_margin_rad", "below", 0.0, "deg", 1e-8, "U",
              "the aircraft's own ground-contact bank: the low wing's nacelle or wingtip touching the runway at the "
              "touchdown pitch with the main gear strut at its static compression (the aircraft file's "
              "[ground_contact] points: the JSBSim model's engine stations, span and gear, and a nacelle clearance "
              "and wing outline not yet read in a Boeing ground-clearance table, U). Probability: the bank "
              "criterion's 1e-8 (" + SMAC + "p5, the roll angle standing for wing or nacelle contact)",
              "low-wing nacelle or wingtip below the runway at touchdown (bank beyond the contact bank at the "
              "touchdown pitch; unverified geometry)"),
    Criterion("gear_slip", "td_gear_slip_rad", "abs_above", math.radians(14.0), "deg", 1e-6, "S",
              SMAC + "p6 = prob(|SSTP| > 14 deg), main landing gear sideslip angle at touchdown, average risk "
              "< 1e-6",
              "main-gear slip angle (ground track minus heading) above 14 deg at touchdown"),
)
"""The criteria scored by default. None is marked V: AC 120-28D's and CS-AWO's own numbers were not found
(docs/touchdown.md), so every verdict is `unverified_limit`."""

QUANTITIES = {
    "td_x_m": ("x_ft", "ft", "longitudinal touchdown point of the main gear, past the threshold"),
    "td_y_m": ("y_ft", "ft", "main-gear centre, right of the centreline"),
    "td_left_gear_y_m": ("left_gear_y_ft", "ft", "left main gear, right of the centreline"),
    "td_right_gear_y_m": ("right_gear_y_ft", "ft", "right main gear, right of the centreline"),
    "td_outboard_gear_y_m": ("outboard_gear_y_ft", "ft", "outboard main gear (the one farther out), right of the "
                             "centreline: bimodal by construction, not normal"),
    "td_sink_mps": ("sink_fps", "ft/s", "sink rate of the main gear that touched"),
    "td_imu_x_m": ("imu_x_ft", "ft", "IMU point past the threshold at main-gear touchdown"),
    "td_imu_y_m": ("imu_y_ft", "ft", "IMU point right of the centreline"),
    "td_imu_sink_mps": ("imu_sink_fps", "ft/s", "IMU point's sink rate"),
    "td_gear_height_m": ("gear_height_ft", "ft", "the touching main gear's height above the threshold (check: ~0)"),
    "td_bank_rad": ("bank_deg", "deg", "bank angle"),
    "td_pitch_rad": ("pitch_deg", "deg", "pitch angle"),
    "td_crab_rad": ("crab_deg", "deg", "heading minus runway heading"),
    "td_gear_slip_rad": ("gear_slip_deg", "deg", "main-gear ground track minus heading"),
    "td_cas_mps": ("cas_kt", "kt", "calibrated airspeed"),
    "td_contact_bank_rad": ("contact_bank_deg", "deg", "bank at which the low wing's nacelle or wingtip touches the "
                            "runway at the touchdown pitch (gear strut at its static compression)"),
    "td_contact_margin_rad": ("contact_margin_deg", "deg", "contact bank less the bank at touchdown"),
}
"""Per-run column -> (details.json name, display unit, what) of the quantities summarised."""

PERCENTILES = (1, 5, 25, 50, 75, 95, 99)
NORMALITY_ALPHA = 0.05
"""Shapiro-Wilk p-value below which normality is rejected (and no criterion can come out `within`)."""


# --- statistics --------------------------------------------------------------------------------------------------


@lru_cache(maxsize=512)
def _w_law(df: int) -> tuple[float, float, float]:
    """Integration range (the 1e-15 and 1 - 1e-15 quantiles) and log normalizing constant of W = sqrt(V / df),
    V ~ chi2(df): f_W(w) = 2 (df/2)^(df/2) / Gamma(df/2) w^(df-1) exp(-df w^2 / 2)."""
    w = sps.chi(df, scale=1.0 / math.sqrt(df))
    log_c = math.log(2.0) + 0.5 * df * math.log(0.5 * df) - math.lgamma(0.5 * df)
    return float(w.ppf(1e-15)), float(w.isf(1e-15)), log_c


def nct_sf(t: float, df: int, delta: float) -> float:
    """P(T >= t) for T noncentral t with df degrees of freedom and noncentrality delta: T = (Z + delta) / W,
    so P = E[Phi(delta - t W)], integrated over W's density by adaptive quadrature (scipy's nct.sf loses
    convergence for large noncentralities and negative t; this agrees with it to 1e-13 where it converges)."""
    a, b, log_c = _w_law(df)
    r2 = math.sqrt(2.0)

    def f(w: float) -> float:
        return 0.5 * math.erfc((t * w - delta) / r2) * math.exp(log_c + (df - 1) * math.log(w) - 0.5 * df * w * w)

    pts = None
    if t != 0.0 and a < delta / t < b:
        pts = [delta / t]  # where Phi(delta - t w) steps from 1 to 0
    return float(quad(f, a, b, points=pts, limit=200, epsabs=1e-14, epsrel=1e-11)[0])


def _delta_bound(t_obs: float, df: int, tail: float, upper: bool) -> float:
    """The noncentrality delta of a noncentral t (df) with P(T >= t_obs) = tail (upper=False: the lower
    confidence bound of delta) or P(T <= t_obs) = tail (upper=True: the upper bound); nct_sf increases with
    delta."""
    if upper:
        f = lambda d: (1.0 - nct_sf(t_obs, df, d)) - tail  # noqa: E731
    else:
        f = lambda d: nct_sf(t_obs, df, d) - tail  # noqa: E731
    width = 8.0 * math.sqrt(1.0 + t_obs * t_obs / (2.0 * df)) + 8.0
    lo, hi = t_obs - width, t_obs + width
    for _ in range(60):
        if f(lo) * f(hi) < 0.0:
            return float(brentq(f, lo, hi, xtol=1e-10, rtol=1e-12))
        lo, hi = lo - width, hi + width
    raise ArithmeticError(f"no noncentrality bracket for t = {t_obs}, df = {df}")


def upper_tail_bounds(z: float, n: int, level: float) -> tuple[float, float, float]:
    """(point, lower, upper) of P(X > L) for X ~ N(mu, sigma^2), from n values whose mean and sd (ddof 1) put
    L at z = (L - mean) / sd: Phi(-z) and the exact one-sided bounds at `level` each (module docstring: the
    noncentral t of the normal tolerance limit, T = sqrt(n) z, noncentrality sqrt(n) (L - mu) / sigma)."""
    root = math.sqrt(n)
    t_obs = root * z
    d_lo = _delta_bound(t_obs, n - 1, 1.0 - level, upper=False)
    d_hi = _delta_bound(t_obs, n - 1, 1.0 - level, upper=True)
    return float(sps.norm.sf(z)), float(sps.norm.sf(d_hi / root)), float(sps.norm.sf(d_lo / root))


def upper_tail_bounds_wald(z: float, n: int, level: float) -> tuple[float, float, float]:
    """upper_tail_bounds' large-sample (Wald) form: z -+ q sqrt(1/n + z^2 / (2 (n - 1))), q = Phi^-1(level),
    the standard deviation of mean + z sd to first order (the Johnson-Welch tolerance factor inverted); used for
    run-count planning only."""
    half = float(sps.norm.ppf(level)) * math.sqrt(1.0 / n + z * z / (2.0 * (n - 1)))
    return float(sps.norm.sf(z)), float(sps.norm.sf(z + half)), float(sps.norm.sf(z - half))


Fit = tuple[float, float]
"""(mean, sd) of a fitted normal, SI."""


def _tail_zs(crit: Criterion, fit: Fit, low: Fit | None = None) -> tuple[float, ...]:
    """Per tail of the criterion, its limit's distance from the mean in sd towards that tail (abs_above: the
    lower tail from `low` when given, the lower quantity's fit)."""
    mean, sd = fit
    if crit.side == "above":
        return ((crit.limit - mean) / sd,)
    if crit.side == "below":
        return ((mean - crit.limit) / sd,)
    ml, sl = fit if low is None else low
    return ((crit.limit - mean) / sd, (crit.limit + ml) / sl)


def tail_bounds(crit: Criterion, mean: float, sd: float, n: int, level: float, exact: bool = True,
                low: Fit | None = None) -> tuple[float, float, float]:
    """(point, lower, upper) of the criterion's exceedance probability under the fitted normal (two-sided
    criteria: both tails added, each bounded at 1 - (1 - level) / 2; low: the lower quantity's (mean, sd));
    exact=False: the Wald form."""
    zs = _tail_zs(crit, (mean, sd), low)
    lvl = level if len(zs) == 1 else 1.0 - (1.0 - level) / 2.0
    f = upper_tail_bounds if exact else upper_tail_bounds_wald
    parts = [f(z, n, lvl) for z in zs]
    if len(parts) == 1:
        return parts[0]
    return (sum(p[0] for p in parts), max(p[1] for p in parts), min(1.0, sum(p[2] for p in parts)))


def z_of_limit(crit: Criterion, mean: float, sd: float, low: Fit | None = None) -> float:
    """The limit's distance from the mean in standard deviations, on the exceedance side (two-sided: the
    nearer limit); larger is safer."""
    return min(_tail_zs(crit, (mean, sd), low))


def z_required(probability: float) -> float:
    """Standard deviations from the mean a one-sided limit must lie at for a normal to exceed it with
    `probability`: Phi^-1(1 - p) (4.753 for 1e-6)."""
    return float(sps.norm.isf(probability))


def runs_to_decide(crit: Criterion, mean: float, sd: float, level: float, n_max: int = 10**9,
                   low: Fit | None = None) -> int | None:
    """Landings at which the normal bounds would likely decide the criterion if the mean and sd stayed where
    they are (Wald form of the bounds): towards `within` when the point probability is within the required one
    (the upper bound reaches it), towards `exceeds` otherwise (the lower bound passes it); None when the point
    probability equals the requirement or more than n_max landings would be needed."""

    def bounds(n: int) -> tuple[float, float, float]:
        return tail_bounds(crit, mean, sd, n, level, exact=False, low=low)

    p = bounds(3)[0]
    if p == crit.probability:
        return None
    if p < crit.probability:
        ok = lambda n: bounds(n)[2] <= crit.probability  # noqa: E731
    else:
        ok = lambda n: bounds(n)[1] > crit.probability  # noqa: E731
    if not ok(n_max):
        return None
    return max(smallest_n(ok, 3, n_max), MIN_RUNS)


def clean_runs_needed(probability: float, level: float) -> int:
    """Runs with no exceedance that show `probability` distribution-free: the n with 1 - (1 - p)^n >= level."""
    return int(math.ceil(math.log(1.0 - level) / math.log1p(-probability)))


def _num(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def normality(x: Array) -> dict:
    """Shapiro-Wilk p-value (n >= 3), skewness and excess kurtosis of a sample (None where undefined)."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size < 3 or float(np.ptp(x)) == 0.0:
        return {"shapiro_p": None, "skewness": None, "excess_kurtosis": None, "rejected": None}
    p = float(sps.shapiro(x).pvalue)
    return {"shapiro_p": p, "skewness": _num(float(sps.skew(x))), "excess_kurtosis": _num(float(sps.kurtosis(x))),
            "rejected": bool(p < NORMALITY_ALPHA)}


def quantity_stats(x_si: Array, factor: float) -> dict:
    """n, mean, sd (ddof 1), min, max and PERCENTILES of the finite values, in the display unit (x factor), with
    the normality check."""
    x = np.asarray(x_si, dtype=float)
    x = x[np.isfinite(x)] * factor
    out: dict = {"n": int(x.size)}
    if x.size == 0:
        return out | {"mean": None, "sd": None, "min": None, "max": None}
    out |= {"mean": float(np.mean(x)), "sd": _num(float(np.std(x, ddof=1))) if x.size > 1 else None,
            "min": float(x.min()), "max": float(x.max())}
    out |= {f"p{p}": float(np.percentile(x, p)) for p in PERCENTILES}
    out["normality"] = normality(x)
    return out


def criterion_result(crit: Criterion, x_si: Array, failed_runs: int, level: float,
                     x_low_si: Array | None = None) -> dict:
    """One criterion over the completed landings' values x_si (SI; x_low_si: the lower_quantity's, same runs)
    and the failed runs (counted as exceedances): empirical and normal-tail figures, outcome and verdict (module
    docstring), JSON-safe, display unit."""
    x = np.asarray(x_si, dtype=float)
    xl = x if x_low_si is None else np.asarray(x_low_si, dtype=float)
    ok = np.isfinite(x) & np.isfinite(xl)
    x, xl = x[ok], xl[ok]
    two = x_low_si is not None and crit.side == "abs_above"
    n = int(x.size)
    runs = n + int(failed_runs)
    k = int(np.count_nonzero(crit.exceeded(x, xl if two else None))) + int(failed_runs)
    e_lo, e_hi = clopper_pearson(k, runs, level)
    f = DISPLAY[crit.unit]
    z_req = z_required(crit.probability)
    res: dict = {
        "what": crit.what,
        "quantity": crit.quantity,
        **({"lower_quantity": crit.lower_quantity} if two else {}),
        "side": crit.side,
        "limit": crit.limit * f,
        "unit": crit.unit,
        "probability_required": crit.probability,
        "z_required": z_req,
        "mark": crit.mark,
        "source": crit.source,
        "runs": runs,
        "failed_runs": int(failed_runs),
        "exceedances": k,
        "empirical": {"fraction": _num(k / runs) if runs else None, "lower": e_lo, "upper": e_hi,
                      "clean_runs_needed": clean_runs_needed(crit.probability, level)},
    }
    normal: dict | None = None
    sd = float(np.std(x, ddof=1)) if n > 1 else 0.0
    sd_l = float(np.std(xl, ddof=1)) if n > 1 else 0.0
    norm_check = normality(x)
    if two:
        low_check = normality(xl)
        if low_check["rejected"] is not None:
            norm_check = {"upper": norm_check, "lower": low_check,
                          "rejected": bool(norm_check["rejected"] or low_check["rejected"])}
    if n >= 3 and sd > 0.0 and sd_l > 0.0:
        mean = float(np.mean(x))
        low = (float(np.mean(xl)), sd_l) if two else None
        p, p_lo, p_hi = tail_bounds(crit, mean, sd, n, level, low=low)
        normal = {
            "n": n, "mean": mean * f, "sd": sd * f,
            **({"lower_mean": low[0] * f, "lower_sd": low[1] * f} if low else {}),
            "z_limit": z_of_limit(crit, mean, sd, low),
            "probability": p, "probability_lower": p_lo, "probability_upper": p_hi,
            "runs_needed": runs_to_decide(crit, mean, sd, level, low=low),
            "normality": norm_check,
        }
    res["normal"] = normal
    if e_lo > crit.probability:
        outcome, why = "exceeds", (f"{k} of {runs} runs exceeded (failed runs count): the empirical lower bound "
                                   f"{e_lo:.2g} is above {crit.probability:g}")
    elif normal is None:
        outcome, why = "indeterminate", "fewer than 3 distinct completed landings: no tail to fit"
    elif norm_check["rejected"]:
        sw = min(c["shapiro_p"] for c in (norm_check.get("upper", norm_check), norm_check.get("lower", norm_check)))
        outcome, why = "indeterminate", (f"normality rejected (Shapiro-Wilk p = {sw:.3g}): the normal tail does not "
                                         "extrapolate")
    elif normal["probability_lower"] > crit.probability:
        outcome, why = "exceeds", (f"the limit lies {normal['z_limit']:.2f} sd from the mean (required {z_req:.2f}): "
                                   f"the fitted normal's lower bound {normal['probability_lower']:.2g} is above "
                                   f"{crit.probability:g}")
    elif normal["probability_upper"] > crit.probability:
        outcome, why = "indeterminate", (
            f"the limit lies {normal['z_limit']:.2f} sd from the mean (required {z_req:.2f} for "
            f"{crit.probability:g}); the upper bound {normal['probability_upper']:.2g} from {n} landings is above "
            f"{crit.probability:g}")
    elif n < MIN_RUNS:
        outcome, why = "indeterminate", f"fewer than {MIN_RUNS} completed landings"
    else:
        outcome, why = "within", (f"no exceedance; the normal upper bound {normal['probability_upper']:.2g} is "
                                  f"within {crit.probability:g} (normal-tail extrapolation from {n} landings)")
    res["outcome"] = outcome
    res["why"] = why
    if crit.verified:
        res["verdict"] = {"within": "meets", "exceeds": "fails"}.get(outcome, "indeterminate")
    else:
        res["verdict"] = "unverified_limit"
    return res


def overall_verdict(results: Mapping[str, dict]) -> str:
    """`fails` when a verified criterion fails; `meets` when every criterion is verified and meets;
    `unverified_limits` when any criterion's limit is unverified (and no verified one fails); else
    `indeterminate`."""
    v = [r["verdict"] for r in results.values()]
    if "fails" in v:
        return "fails"
    if "unverified_limit" in v:
        return "unverified_limits"
    return "meets" if v and all(x == "meets" for x in v) else "indeterminate"


def touchdown_details(columns: Mapping[str, Array], *, runs: int, failed_runs: int, level: float,
                      criteria: Sequence[Criterion] = CRITERIA) -> dict:
    """details.json "touchdown": the campaign's touchdown statistics and criteria (module docstring) from the
    per-run columns of the completed landings (touchdown_scalars' names) and the failed-run count."""
    quantities = {}
    for col, (name, unit, what) in QUANTITIES.items():
        x = np.asarray(columns.get(col, np.empty(0)), dtype=float)
        factor = 1.0 / units.KT if unit == "kt" else DISPLAY[unit]
        quantities[name] = {"unit": unit, "what": what, **quantity_stats(x, factor)}
    def col(name: str | None) -> Array | None:
        return None if name is None else np.asarray(columns.get(name, np.empty(0)), dtype=float)

    crit = {c.key: criterion_result(c, col(c.quantity), failed_runs, level, col(c.lower_quantity))
            for c in criteria}
    landings = int(np.count_nonzero(np.isfinite(np.asarray(columns.get("td_x_m", np.empty(0)), dtype=float))))
    return {
        "runs": int(runs),
        "landings": landings,
        "failed_runs": int(failed_runs),
        "confidence": level,
        "verdict": overall_verdict(crit),
        "criteria_verified": sum(c.verified for c in criteria),
        "quantities": quantities,
        "criteria": crit,
        "method": "docs/touchdown.md",
    }


def touchdown_summary(td: Mapping) -> dict:
    """summary.json "touchdown" (landing campaigns): the headline of details.json "touchdown"."""
    q = td["quantities"]
    return {
        "landings": td["landings"],
        "failed_runs": td["failed_runs"],
        "x_mean_ft": q["x_ft"].get("mean"),
        "x_sd_ft": q["x_ft"].get("sd"),
        "sink_mean_fps": q["sink_fps"].get("mean"),
        "sink_max_fps": q["sink_fps"].get("max"),
        "outboard_gear_abs_max_ft": (None if q["outboard_gear_y_ft"].get("n", 0) == 0 else
                                     max(abs(q["outboard_gear_y_ft"]["min"]), abs(q["outboard_gear_y_ft"]["max"]))),
        "verdict": td["verdict"],
        "criteria_verified": td["criteria_verified"],
        "outcomes": {k: c["outcome"] for k, c in td["criteria"].items()},
    }
