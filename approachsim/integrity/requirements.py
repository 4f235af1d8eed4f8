"""The one requirements table: integrity, alert limits and continuity per approach category, what each row models,
and the multipliers and thresholds derived from it. evaluate/limits.py takes its alert limits from here.

Rows (the project's reference notes, integrity-envelope.md sec. 1-3, with their confidence marks):

| row | models | integrity risk (exposure vert. / lat.) | TTA | continuity | LAL / VAL at DH |
|---|---|---|---|---|---|
| CAT I | GAST-C, LAAS-style PL | 2e-7 / approach (150 s) [S] | 6 s [V] | 8e-6 / 15 s [V] | 40 / 10 m (*) [V] |
| CAT II, III | GSL D/E AL, LAAS-style PL | 1e-9 / 15 s v., 30 s lat. [S] | 2 s [S] | 8e-6 / 15 s [S] | 17 / 10 m [S] |
| LPV-200 | SBAS, DO-229 App. J PLs | 2e-7 / approach (150 s) [V] | 6 s [V] | 8e-6 / 15 s [V] | 40 / 35 m [V] |

(*) with distance and height, Annex 10 App. B Tables B-68 / B-69.

[V]: ICAO Annex 10 Vol I (2006 copy); [S]: RTCA DO-245A Table 2-1 via Pullen (Stanford) slides: check against
the standards before a certification claim rests on them.

What "LAAS-style 1e-9 PL, not GAST-D" means: the CAT II / III rows bound the error by one protection level per axis
at the 1e-9 allocation (fault-free K_ff sigma, faulted max_k (T_k + K_md sigma_k) over the airborne bank's modes)
and compare it with GAST-D's 17 / 10 m alert limits. GAST-D itself does not work that way: its integrity rests on
ground and airborne monitors (ionospheric gradients, geometry screening with D_V, dual smoothing) and the
autoland's total-system allocation, none of which is modelled. The older LAAS performance-type limits (CAT II/IIIA
17.3 / 5.3 m, CAT IIIB 15.5 / 5.2 m, integrity-envelope.md 1b) were used by evaluate/limits.py until issue 41 and
are in no row now.

Availability (IntegrityRequirement.availability, `availability_covers`): PL < AL with the bank's fault modes, which
in `approachsim evaluate` are single GPS satellite (channel) faults only: no baro, radar-altimeter, pseudolite,
constellation-wide or ground-subsystem fault is among the hypotheses the PL protects against.

Derived here (each a function with its equation):

* effective independent samples over the exposure N_es = exposure / TTA (ARAIM ADD v4.2 practice);
* the integrity risk split evenly between the fault-free (H0) and the faulted (H1) hypotheses and between the
  vertical and lateral axes;
* fault-free multiplier K_ff = Q^-1(P_H0 / (2 N_es)) (two-sided Gaussian tail per effective sample;
  Q^-1 = scipy.stats.norm.isf);
* false-alert probability per test and filter epoch from the continuity budget: the budget per 15 s spread
  over the epochs in 15 s (1 Hz filter: 15) and the monitors' tests: P_fa = C / (15 f n_tests); the
  chi-square residual threshold chi2.isf(P_fa, dof) and the solution-separation threshold
  K_fa = Q^-1(P_fa / 2);
* missed-detection probability P_md = P_H1,axis / (N_es n_modes P_fault) and multiplier K_md = Q^-1(P_md): the
  faulted allocation spread over the n_modes monitored fault modes, each with the prior probability of a
  satellite fault per approach P_fault (1e-5 per satellite, the ARAIM ISM value [S]) (ARAIM ADD: the H1 budget
  is shared by the modes in proportion to their priors).

With the CAT I numbers this gives K_ff = 6.00 (a two-sided tail of 2e-9 per effective sample), K_md = 3.54 for one
mode and, at 1 Hz with six tests, K_fa = 5.35; CAT II/III K_ff = 6.63, P_md = 3.3e-6 and K_md = 4.50 for one mode,
P_md = 3.3e-7 and K_md = 4.97 for ten: against the SBAS K_V = 5.33 (1e-7) the project used for every category
before (still the covariance-only factor, COVARIANCE_K_V, when integrity is off: no fault hypothesis).

Alert limits (vertical_alert_limit_m, lateral_alert_limit_m) and the HMI windows (hmi_window_s): the CAT II / III
integrity event is counted in the last 15 s (vertical) / 30 s (lateral) before the decision height, the exposure
its allocation is stated over; CAT I's over the approach (its 150 s).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np
from scipy.stats import chi2, norm

from approachsim import units


@functools.lru_cache(maxsize=256)
def _q_inv(p: float) -> float:
    """Q^-1(p) = norm.isf(p), kept per p: the bank and the scoring ask for the same few quantiles every run (225
    scipy calls of ~0.2 ms a 25-run group)."""
    return float(norm.isf(p))


AVAILABILITY_COVERS = ("single GPS satellite (channel) faults only: no baro, radar-altimeter, pseudolite, "
                       "constellation-wide or ground-subsystem fault")
"""The fault modes `approachsim evaluate`'s availability (PL < AL from the solution-separation bank) covers."""


@dataclass(frozen=True)
class IntegrityRequirement:
    """One category's integrity requirement (SI)."""

    category: str
    integrity_risk: float
    """Probability of hazardously misleading information over the exposure (both axes, all hypotheses)."""
    exposure_s: float
    time_to_alert_s: float
    continuity_risk_per_15s: float
    lal_m: float
    """Lateral alert limit at the decision height (CAT I: at the threshold end of Table B-68's scaling), m."""
    val_m: float
    """Vertical alert limit at the decision height, m."""
    scaled: bool
    """True: the alert limits grow with distance / height as Annex 10 App. B Tables B-68 / B-69."""
    p_fault_per_sat: float = 1e-5
    """Prior probability of a satellite fault over an approach (ARAIM ISM P_sat, [S])."""
    availability: float = 0.99
    """Availability the category must reach at the decision height: the lower end of ICAO Annex 10 Vol I
    Table 3.7.2.4-1's 0.99 to 0.99999 range (APV and CAT I [V]; the same range is used for CAT II / III)."""
    lateral_exposure_s: float | None = None
    """Lateral exposure, s (None: exposure_s). CAT II / III: 30 s (DO-245A GSL D via Pullen [S])."""
    model: str = ""
    """What the row models (module docstring), in words a report can print."""
    source: str = ""
    """Where its numbers come from, with their confidence marks."""
    availability_covers: str = AVAILABILITY_COVERS
    """The fault modes the availability (PL < AL) protects against."""

    @property
    def vertical_exposure_s(self) -> float:
        """Vertical exposure, s: the window the vertical integrity event is counted in before the DH."""
        return self.exposure_s

    @property
    def lateral_window_s(self) -> float:
        """Lateral exposure, s: the window the lateral integrity event is counted in before the DH."""
        return self.exposure_s if self.lateral_exposure_s is None else self.lateral_exposure_s

    def hmi_window_s(self) -> tuple[float, float] | None:
        """(vertical, lateral) windows before the DH in which HMI is the integrity event, s; None: the whole
        scored approach (CAT I: its allocation is per approach)."""
        return None if self.scaled else (self.vertical_exposure_s, self.lateral_window_s)

    @property
    def hmi_probability_allowed(self) -> float:
        """Allowed probability of the integrity event per approach: HMI anywhere in the approach (CAT I) or in the
        windows before the DH (CAT II / III, hmi_window_s): the row's integrity risk over its exposure."""
        return self.integrity_risk

    def hmi_rate_per_epoch(self, epoch_hz: float) -> float:
        """Allowed rate of hazardously misleading epochs: the integrity risk over the exposure spread over its
        epochs, integrity_risk / (exposure_s epoch_hz) (union bound: any misleading epoch is an event). Epoch
        counting, kept in details.json for comparison; the verdict counts per approach (hmi_probability_allowed)."""
        return self.integrity_risk / max(1.0, self.exposure_s * epoch_hz)

    @property
    def n_es(self) -> float:
        """Effective independent samples over the exposure: exposure / time to alert."""
        return max(1.0, self.exposure_s / self.time_to_alert_s)

    def p_h0_axis(self) -> float:
        """Fault-free integrity allocation of one axis over the exposure: risk / 4 (H0/H1, vertical/lateral)."""
        return self.integrity_risk / 4.0

    def k_ff(self) -> float:
        """Fault-free multiplier K_ff = Q^-1(P_H0,axis / (2 N_es))."""
        return _q_inv(self.p_h0_axis() / (2.0 * self.n_es))

    def p_fa(self, epoch_hz: float, n_tests: int) -> float:
        """False-alert probability per test and epoch: continuity budget / (15 s x rate x tests)."""
        if epoch_hz <= 0 or n_tests < 1:
            raise ValueError("epoch_hz must be > 0 and n_tests >= 1")
        return self.continuity_risk_per_15s / (15.0 * epoch_hz * n_tests)

    def chi2_threshold(self, dof: int, epoch_hz: float, n_tests: int = 1) -> float:
        """Residual-test threshold on the normalized innovation squared sum, chi2.isf(P_fa, dof)."""
        return float(chi2.isf(self.p_fa(epoch_hz, n_tests), dof))

    def k_fa(self, epoch_hz: float, n_tests: int) -> float:
        """Solution-separation threshold multiplier K_fa = Q^-1(P_fa / 2) (two-sided)."""
        return _q_inv(self.p_fa(epoch_hz, n_tests) / 2.0)

    def p_md(self, n_modes: int = 1) -> float:
        """Missed-detection probability the allocation asks of each mode's detector per effective sample:
        P_md = P_H1,axis / (N_es n_modes P_fault), at most 0.5 (module docstring)."""
        if n_modes < 1:
            raise ValueError("n_modes must be >= 1")
        return min(self.p_h0_axis() / (self.n_es * n_modes * self.p_fault_per_sat), 0.5)

    def k_md(self, n_modes: int = 1) -> float:
        """Missed-detection multiplier K_md = Q^-1(P_md(n_modes)), at least 0."""
        return _q_inv(self.p_md(n_modes))


_CAT1_SOURCE = ("ICAO Annex 10 Vol I Table 3.7.2.4-1 and App. B Tables B-68 / B-69 (AL, TTA, continuity [V]); "
                "integrity 2e-7 per approach and 150 s exposure: DO-245A Table 2-1 GSL C via Pullen [S]")
_CAT23_SOURCE = ("RTCA DO-245A Table 2-1 GSL D / E via Pullen (Stanford) slides [S]: LAL 17 m, VAL 10 m, "
                 "P(LoI) 1e-9 per 15 s vertical / 30 s lateral, TTA 2 s, continuity 8e-6 per 15 s")
_CAT23_MODEL = "DO-245A GSL D/E alert limits with a LAAS-style 1e-9 protection level (not GAST-D)"

ROWS = MappingProxyType({
    "CAT I": IntegrityRequirement(
        "CAT I", 2e-7, 150.0, 6.0, 8e-6, 40.0, 10.0, True,
        model="GBAS CAT I (GAST-C) allocation with a LAAS-style protection level", source=_CAT1_SOURCE),
    "CAT II": IntegrityRequirement(
        "CAT II", 1e-9, 15.0, 2.0, 8e-6, 17.0, 10.0, False, lateral_exposure_s=30.0,
        model=_CAT23_MODEL, source=_CAT23_SOURCE),
    "CAT III": IntegrityRequirement(
        "CAT III", 1e-9, 15.0, 2.0, 8e-6, 17.0, 10.0, False, lateral_exposure_s=30.0,
        model=_CAT23_MODEL, source=_CAT23_SOURCE),
    "LPV-200": IntegrityRequirement(
        "LPV-200", 2e-7, 150.0, 6.0, 8e-6, 40.0, 35.0, False,
        model="SBAS LPV-200 with the DO-229 App. J protection levels (VPL = 5.33 d_V, HPL = 6.0 d_major): its own "
              "summary key (evaluate/lpv.py), not a category",
        source="ICAO Annex 10 Vol I Table 3.7.2.4-1 (APV / LPV-200: HAL 40 m, VAL 35 m, 2e-7 per approach, TTA 6 s, "
               "continuity 8e-6 / 15 s) [V]"),
})
"""Every modelled row of the one requirements table (module docstring), by name."""

REQUIREMENTS = MappingProxyType({c: ROWS[c] for c in ("CAT I", "CAT II", "CAT III")})
"""The row each approach category is scored against (evaluate and integrity alike)."""

COVARIANCE_K_V = 5.33
"""Vertical factor of the covariance-only protection level K_V sqrt(P_DD) (SBAS DO-229 App. J precision approach,
MAAST init_mops.m; a two-sided 1e-7 fault-free tail). Used only with integrity off: no fault hypothesis, so not
integrity evidence, and not any category's allocation (K_ff above)."""
COVARIANCE_K_H = 6.0
"""Horizontal factor of the covariance-only protection level K_H d_major (SBAS DO-229 App. J; 2e-9 along the
major axis). Used only with integrity off (COVARIANCE_K_V)."""


def lateral_alert_limit_m(req: IntegrityRequirement, distance_m: np.ndarray | float) -> np.ndarray:
    """Lateral alert limit (m) at horizontal distance D (m) from the landing threshold along the final approach
    path. Scaled (CAT I, Annex 10 App. B Table B-68, FASLAL = req.lal_m): FASLAL for D <= 873 m,
    0.0044 D + FASLAL - 3.85 for 873 < D <= 7500 m, FASLAL + 29.15 beyond. Otherwise constant."""
    d = np.abs(np.asarray(distance_m, dtype=float))
    if not req.scaled:
        return np.full_like(d, req.lal_m)
    return np.where(d <= 873.0, req.lal_m, np.where(d <= 7500.0, 0.0044 * d + req.lal_m - 3.85, req.lal_m + 29.15))


def vertical_alert_limit_m(req: IntegrityRequirement, height_m: np.ndarray | float) -> np.ndarray:
    """Vertical alert limit (m) at height H above the threshold on the final approach path. Scaled (CAT I,
    Annex 10 App. B Table B-69, FASVAL = req.val_m): FASVAL for H <= 200 ft, 0.02925 H(ft) + FASVAL - 5.85 for
    200 < H <= 1340 ft, FASVAL + 33.35 above (the table starts at 100 ft; below, FASVAL is kept)."""
    h_ft = np.asarray(height_m, dtype=float) / units.FT
    if not req.scaled:
        return np.full_like(h_ft, req.val_m)
    return np.where(h_ft <= 200.0, req.val_m,
                    np.where(h_ft <= 1340.0, 0.02925 * h_ft + req.val_m - 5.85, req.val_m + 33.35))


def gaussian_tail_two_sided(k: float) -> float:
    """P(|X| > k sigma) of a Gaussian, 2 Q(k): the probability a multiplier k stands for."""
    return float(2.0 * norm.sf(k))


def describe(req: IntegrityRequirement, epoch_hz: float = 1.0, n_tests: int = 1, n_modes: int = 1
             ) -> dict[str, float]:
    """The derived numbers of one category (for reports): K_ff, K_md and P_md for n_modes fault modes, K_fa, P_fa,
    N_es, the exposures."""
    return {
        "k_ff": req.k_ff(),
        "k_md": req.k_md(n_modes),
        "p_md": req.p_md(n_modes),
        "n_modes": float(n_modes),
        "vertical_exposure_s": req.vertical_exposure_s,
        "lateral_exposure_s": req.lateral_window_s,
        "k_fa": req.k_fa(epoch_hz, n_tests),
        "p_fa_per_test_epoch": req.p_fa(epoch_hz, n_tests),
        "n_es": req.n_es,
        "time_to_alert_s": req.time_to_alert_s,
        "lal_at_dh_m": req.lal_m,
        "val_at_dh_m": req.val_m,
        "tail_k_ff": gaussian_tail_two_sided(req.k_ff()),
        "log10_integrity_risk": math.log10(req.integrity_risk),
    }
