"""Rare-event estimation of a failure probability P(g(U) > 0), U ~ N(0, I_d): plain Monte Carlo, cross-entropy
importance sampling and non-parametric adaptive importance sampling, with the likelihood-ratio estimator, its
coefficient of variation and confidence bounds.

The estimators are OpenTURNS's (a maintained library; UQpy pins numpy 1.26 and torch, which the project's numpy 2.x
rules out): `StandardSpaceCrossEntropyImportanceSampling` (Rubinstein & Kroese, *The cross-entropy method*: a
Gaussian auxiliary density moved, step by step, onto the rho-quantile of g until the quantile passes the threshold)
and `NAIS` (Morio, *Non-parametric adaptive importance sampling for the probability estimation of a launcher impact
position*: the same multilevel scheme with a Gaussian-kernel mixture fitted to the weighted elite samples, so it
can follow several failure regions). Both end with the importance-sampling estimate over the last step's N
samples u_i ~ h:

    p_hat = (1 / N) sum_i w_i 1{g(u_i) > 0},    w_i = phi(u_i) / h(u_i)          (likelihood ratio)
    Var(p_hat) = (1 / N) Var_h(w 1{g > 0}),     CoV = sqrt(Var(p_hat)) / p_hat

The same weighted last-step sample estimates any other event g_j(u) > 0 whose region it covers (`reweight`): one
estimator run targets the union of several events (e.g. HMI in any category) and gives each event's probability.
Plain Monte Carlo (`method="mc"`) is the brute force the estimators are validated against (Clopper-Pearson
bounds). OpenTURNS's `SubsetSampling` (Au & Beck, *Estimation of small failure probabilities in high dimensions
by subset simulation*) is not offered: on the Q(6) check case below, at 2000 samples per level, its OpenTURNS
1.27 implementation took 27 levels and returned 1.4e-27 for 9.9e-10 (benchmarks/rare_event_coverage.py shows it,
with the coverage of the two IS methods: NAIS 24-29 of 30 seeds inside the 90 % interval, CE-IS 6-25 of 30 and
biased low).

Bounds. CE-IS and NAIS: the normal approximation of p_hat, each one-sided bound at `level` (p_hat -/+ z sd, the
lower clipped at 0); valid when the last step holds enough failure samples, so an estimate with fewer than
`MIN_HITS` of them, or whose algorithm did not reach the threshold, is not used (`shown` False). Then the
first step, which samples the input distribution itself, is plain Monte Carlo and gives a valid Clopper-Pearson
upper bound (`upper`), the only bound claimed. Plain MC: Clopper-Pearson at `level`.

Check cases (tests/unit/integrity/test_rare.py): P(U0 + 0.5 U1 > 6 sqrt(1.25)) = Q(6) = 9.87e-10 (the reference
notes' OpenTURNS check), and a Gaussian protection-level case with an exact answer.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy import stats as sps

Array = np.ndarray

METHODS = ("nais", "ce", "mc")
"""Estimators by name: NAIS, cross-entropy IS (standard space), plain Monte Carlo."""

MIN_HITS = 10
"""Fewest last-step failure samples for an IS estimate to be used (its normal interval is poor below)."""


def clopper_pearson(k: int, n: int, level: float) -> tuple[float, float]:
    """One-sided Clopper-Pearson (lower, upper) bounds, each at `level`, of a proportion k / n."""
    if n <= 0:
        return 0.0, 1.0
    lo = 0.0 if k <= 0 else float(sps.beta.ppf(1.0 - level, k, n - k + 1))
    hi = 1.0 if k >= n else float(sps.beta.ppf(level, k + 1, n - k))
    return lo, hi


@dataclass(frozen=True)
class Estimate:
    """A probability estimate with its uncertainty and cost."""

    method: str
    probability: float
    """The estimate (nan when the method gave none)."""
    cov: float
    """Its coefficient of variation (nan when there is none)."""
    lower: float
    """One-sided lower bound at `level`."""
    upper: float
    """One-sided upper bound at `level` (1.0 when nothing bounds it)."""
    level: float
    calls: int
    """Evaluations of the limit-state function spent."""
    steps: int
    """Sampling steps (IS: adaptation steps + the final one; MC: 1)."""
    hits: int
    """Failure samples in the sample the estimate rests on (the last step; MC: all)."""
    samples: int
    """Size of that sample."""
    shown: bool
    """True when `probability` and its bounds rest on the estimator (see module docstring); False: only `upper`
    (the first step's Monte Carlo bound) is claimed."""
    note: str = ""
    design_point_u: tuple[float, ...] | None = None
    """Mean of the last step's failure samples, weighted by their likelihood ratio (standard space): the most likely
    failure region, i.e. the worst profile (None without failure samples)."""

    def as_dict(self) -> dict:
        """JSON-ready (nan and inf as None)."""
        def num(x: float) -> float | None:
            return float(x) if x is not None and math.isfinite(x) else None

        return {"method": self.method, "probability": num(self.probability), "cov": num(self.cov),
                "lower": num(self.lower), "upper": num(self.upper), "level": self.level, "calls": self.calls,
                "steps": self.steps, "hits": self.hits, "samples": self.samples, "shown": self.shown,
                "note": self.note,
                "design_point_u": None if self.design_point_u is None else [float(x) for x in self.design_point_u]}


@dataclass
class _Recorder:
    """The limit-state function as OpenTURNS calls it, with every call's inputs and outputs kept in order."""

    g: Callable[[Array], Array]
    dim: int
    budget: int
    inputs: list[Array] = field(default_factory=list)
    outputs: list[Array] = field(default_factory=list)
    calls: int = 0

    def __call__(self, x: object) -> list[list[float]]:
        u = np.array(x, dtype=float).reshape(-1, self.dim)
        if self.calls and self.calls + u.shape[0] > self.budget:
            raise RuntimeError(f"budget of {self.budget} evaluations spent before the threshold was reached")
        y = np.asarray(self.g(u), dtype=float).reshape(-1)
        if y.shape[0] != u.shape[0]:
            raise ValueError("limit-state function: one value per input row expected")
        y = np.nan_to_num(y, nan=-1e6, posinf=1e6, neginf=-1e6)
        self.inputs.append(u)
        self.outputs.append(y)
        self.calls += u.shape[0]
        return y[:, None].tolist()


def estimate(
    g: Callable[[Array], Array], dim: int, *, method: str = "nais", samples: int = 1000, rho: float = 0.1,
    seed: int = 0, level: float = 0.95, max_calls: int | None = None, events: Callable[[Array], Array] | None = None,
) -> tuple[Estimate, dict]:
    """Estimate P(g(U) > 0), U ~ N(0, I_dim); g maps (n, dim) to (n,) (a batch: one call runs many evaluations).

    method: "nais", "ce" or "mc"; samples: per step (IS) or in all (MC); rho: the quantile level of the adaptive
    steps; max_calls: stop adapting after this many evaluations (default 20 steps). Returns (the estimate,
    the final sample: {"u" (N, dim), "g" (N,), "w" (N,) likelihood ratios, "first_u", "first_g"} for `reweight`).
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if samples < 2 or dim < 1 or not 0.0 < rho < 0.5 or not 0.5 < level < 1.0:
        raise ValueError("estimate: samples >= 2, dim >= 1, 0 < rho < 0.5 and 0.5 < level < 1 required")
    import openturns as ot

    ot.RandomGenerator.SetSeed(int(seed) % (2**31))
    rec = _Recorder(g, dim, max_calls if max_calls is not None else 20 * samples)
    if method == "mc":
        u = np.asarray(ot.Normal(dim).getSample(samples))
        y = np.asarray(rec(u)).reshape(-1)
        k = int(np.sum(y > 0.0))
        lo, hi = clopper_pearson(k, samples, level)
        p = k / samples
        cov = math.sqrt((1.0 - p) / (p * samples)) if k else math.nan
        w = np.ones(samples)
        est = Estimate("mc", p, cov, lo, hi, level, rec.calls, 1, k, samples, True,
                       design_point_u=_design_point(u, y, w))
        return est, {"u": u, "g": y, "w": w, "first_u": u, "first_g": y}

    f = ot.PythonFunction(dim, 1, func_sample=rec)
    event = ot.ThresholdEvent(ot.CompositeRandomVector(f, ot.RandomVector(ot.Normal(dim))), ot.Greater(), 0.0)
    algo = (ot.NAIS(event, rho) if method == "nais" else ot.StandardSpaceCrossEntropyImportanceSampling(event, rho))
    algo.setMaximumOuterSampling(1)
    algo.setBlockSize(samples)  # each step is one batch of `samples` evaluations
    # (the budget is enforced by the recorder raising: OpenTURNS 1.27's setStopCallback ends the process)
    note = ""
    try:
        algo.run()
        res = algo.getResult()
        p = float(res.getProbabilityEstimate())
        var = float(res.getVarianceEstimate())
    except RuntimeError as e:  # e.g. every sample on the same value: the quantile step cannot move
        res, p, var, note = None, math.nan, math.nan, f"the estimator stopped: {str(e).splitlines()[0][:160]}"
    first_u, first_g = rec.inputs[0], rec.outputs[0]
    steps = len(rec.inputs)
    # the algorithm stops on the step whose (1 - rho)-quantile passes the threshold
    reached = res is not None and not _quantile_short(rec, rho)
    if res is not None and not reached and not note:
        note = f"the threshold was not reached in {steps} steps ({rec.calls} calls)"
    u_last, g_last = rec.inputs[-1], rec.outputs[-1]
    if steps == 1:  # the first step already had rho N failures: the estimate is plain MC on the input distribution
        w = np.ones(u_last.shape[0])
    elif res is not None:
        aux = res.getAuxiliaryDistribution() if method == "ce" else None
        w = _weights(res, aux, u_last, dim, method)
    else:
        w = np.full(u_last.shape[0], np.nan)
    k = int(np.sum(g_last > 0.0))
    k1 = int(np.sum(first_g > 0.0))
    mc_hi = clopper_pearson(k1, first_g.size, level)[1]
    shown = reached and k >= MIN_HITS and math.isfinite(p) and p > 0.0 and np.all(np.isfinite(w))
    if shown:
        sd = math.sqrt(max(var, 0.0))
        z = float(sps.norm.ppf(level))
        est = Estimate(method, p, sd / p, max(0.0, p - z * sd), min(1.0, p + z * sd), level, rec.calls, steps, k,
                       u_last.shape[0], True, note, _design_point(u_last, g_last, w))
    else:
        if reached and k < MIN_HITS:
            note = note or f"{k} failure samples in the last step (< {MIN_HITS})"
        note = (note + "; " if note else "") + f"upper bound from the first step's Monte Carlo: {k1} of {first_g.size}"
        est = Estimate(method, p if reached else math.nan, math.nan, 0.0, mc_hi, level, rec.calls, steps, k,
                       u_last.shape[0], False, note, _design_point(u_last, g_last, w) if reached else None)
    return est, {"u": u_last, "g": g_last, "w": w, "first_u": first_u, "first_g": first_g}


def _quantile_short(rec: _Recorder, rho: float) -> bool:
    """True when the last step's rho-quantile is still below the threshold (the budget ran out first)."""
    y = rec.outputs[-1]
    return float(np.quantile(y, 1.0 - rho)) < 0.0


def _weights(res: object, aux: object, u: Array, dim: int, method: str) -> Array:
    """Likelihood ratios phi(u) / h(u) of the last step's sample (NAIS: as OpenTURNS computed them)."""
    if method == "nais":
        w = np.asarray(res.getWeights(), dtype=float).reshape(-1)  # type: ignore[attr-defined]
        if w.size == u.shape[0]:
            return w
    import openturns as ot

    logf = np.asarray(ot.Normal(dim).computeLogPDF(u), dtype=float).reshape(-1)
    dist = aux if aux is not None else res.getAuxiliaryDistribution()  # type: ignore[attr-defined]
    logh = np.asarray(dist.computeLogPDF(u), dtype=float).reshape(-1)
    return np.exp(logf - logh)


def _design_point(u: Array, y: Array, w: Array) -> tuple[float, ...] | None:
    hit = y > 0.0
    if not hit.any() or not np.all(np.isfinite(w[hit])) or np.sum(w[hit]) <= 0:
        return None
    return tuple(float(x) for x in np.average(u[hit], axis=0, weights=w[hit]))


def reweight(indicator: Array, w: Array, level: float = 0.95) -> dict:
    """The importance-sampling estimate of another event from a weighted sample: p = mean(w 1), its standard error,
    CoV and one-sided normal bounds at `level`, the failure-sample count; `shown` as for `estimate` (MIN_HITS).
    indicator (N,) bool of the event at the sample points, w (N,) their likelihood ratios."""
    ind = np.asarray(indicator, bool)
    w = np.asarray(w, float)
    n = ind.size
    x = np.where(ind, w, 0.0)
    p = float(np.mean(x))
    sd = float(np.std(x, ddof=1) / math.sqrt(n)) if n > 1 else math.nan
    k = int(ind.sum())
    z = float(sps.norm.ppf(level))
    shown = k >= MIN_HITS and p > 0.0
    return {"probability": p, "sd": sd, "cov": sd / p if p > 0 else None, "hits": k, "samples": n,
            "lower": max(0.0, p - z * sd) if shown else 0.0, "upper": min(1.0, p + z * sd) if shown else None,
            "shown": shown}


def clopper_pearson_eff(k: float, n: float, level: float) -> tuple[float, float]:
    """Clopper-Pearson (lower, upper), each one-sided at `level`, for a possibly non-integer count k of n (the
    effective counts of a weighted sample, `weighted_conditional`); equal to `clopper_pearson` at integers. Both
    bounds rise with k at fixed n and narrow as n grows at a fixed proportion (the beta quantiles are monotone)."""
    if n <= 0:
        return 0.0, 1.0
    k = min(max(float(k), 0.0), float(n))
    lo = 0.0 if k <= 0 else float(sps.beta.ppf(1.0 - level, k, n - k + 1))
    hi = 1.0 if k >= n else float(sps.beta.ppf(level, k + 1, n - k))
    return lo, hi


def weighted_conditional(indicator: Array, w: Array, level: float = 0.95) -> dict:
    """P(event | the samples' region) from an importance-weighted sample restricted to that region: the
    self-normalized ratio p = sum(w 1) / sum(w), Kish's effective sample size n_eff = (sum w)^2 / sum(w^2), and
    Clopper-Pearson bounds on the effective counts (p n_eff of n_eff, `clopper_pearson_eff`). With equal weights it is
    the plain proportion and exact Clopper-Pearson; with unequal ones the bounds are approximate (the effective-size
    argument, Kish 1965; as in the binomial approximation of weighted survey proportions), and a region the proposal
    rarely visits has a small n_eff and so wide bounds. JSON-ready: probability (None without samples), hits (the
    unweighted event count), samples, n_eff, k_eff, lower, upper."""
    ind = np.asarray(indicator, bool)
    w = np.asarray(w, float)
    ok = np.isfinite(w) & (w > 0.0)
    ind, w = ind[ok], w[ok]
    sw = float(np.sum(w))
    if ind.size == 0 or sw <= 0.0:
        return {"probability": None, "hits": 0, "samples": 0, "n_eff": 0.0, "k_eff": 0.0, "lower": 0.0,
                "upper": 1.0}
    p = float(np.sum(w[ind]) / sw)
    n_eff = sw * sw / float(np.sum(w * w))
    lo, hi = clopper_pearson_eff(p * n_eff, n_eff, level)
    return {"probability": p, "hits": int(ind.sum()), "samples": int(ind.size), "n_eff": n_eff,
            "k_eff": p * n_eff, "lower": lo, "upper": hi}


def rms_scale_upper(sum_sq: Array, count: Array, n_eff: int, level: float = 0.95) -> float:
    """One-sided upper bound at `level` of the RMS of normalized errors z = e / sigma from per-run sums of z^2
    (sum_sq) and counts (count): RMS = sqrt(sum sum_sq / sum count), bounded as a chi-square with n_eff degrees of
    freedom (n_eff = runs: the epochs of a run are correlated, and a run of fully correlated epochs is one chi-square
    degree of freedom, so counting runs is conservative). The overbounding factor of a filter covariance."""
    tot = float(np.nansum(count))
    if tot <= 0 or n_eff < 1:
        return math.inf
    rms = math.sqrt(float(np.nansum(sum_sq)) / tot)
    return rms * math.sqrt(n_eff / float(sps.chi2.ppf(1.0 - level, n_eff)))
