"""Filter consistency state by state on a flown approach: which navigation errors the filter over- or under-claims,
and the consistency suite of issue 39 (item 5).

    python tools/consistency_by_state.py PROFILE [--runs 60] [--seed 1] [--set KEY=VALUE ...]
        [--slow-tau-s TAU] [--ideal-imu-axes gyro|accel|gyro,accel] [--filter-turbulence LEVEL]
    python tools/consistency_by_state.py --suite [--runs 60] [--seeds 1 2] [--workers 1] [--out docs/consistency.md]
    python tools/consistency_by_state.py --suite --pool --seeds 1 2 ... 10 [--workers 2] [--out docs/consistency.md]
    python tools/consistency_by_state.py PROFILE --pool --seeds 1 2 ... 20 [--runs 60] [--workers 2]

The profile is flown once on truth; RUNS seeded sensor realizations and open-loop navigation runs (the shared
covariance, as campaigns run) follow on that truth. Printed per state (dp N E D m, dv N E D m/s, psi N E D rad; clk
the receiver clock bias, m): the run-averaged e^2 / P over the approach after its first quarter (1 for a consistent
filter; below 1 the filter over-claims), the fractions of epochs whose run average is inside / below / above the
two-sided 95 % chi2(RUNS)/RUNS bounds, the filter's mean sigma, the run-mean error over the sigma (RMS over the
epochs: about 1 / sqrt(RUNS) when nothing is common to the runs), each run's time-averaged e^2 / P's degrees of
freedom per run and the 95 % sampling interval of the run-averaged ratio they give (summary()); with a GNSS
service's zenith states, giz_0, giz_E, giz_N against the truth's ionospheric field (common part, east and north
gradient per d_5) and gtz against its tropospheric zenith residual (m). --set changes a profile key for this run
(dotted path, a TOML value: --set sensors.gnss.multipath_model='"nrc1995"'). Diagnostics on the truth: --slow-tau-s sets
its clock/ephemeris, iono and tropo time constants to TAU; --ideal-imu-axes removes its gyro and/or accelerometer
scale-factor and misalignment errors. --filter-turbulence builds the filter's gyro scale-factor / misalignment
process noise at another turbulence level (none: the time-constant-only filter, the control of the suite).

--suite runs the cases of SUITE (the default profile, the CAT III candidate, ISA -30 and +30 uncorrected and a
5434 ft field, the last three with the baro scale-factor state) at each seed, the profile's filter and the control
on the same records, and writes the table with the acceptance of issue 39: every state's e^2/P in [0.8, 1.25],
inside its band at >= 90 % of the epochs and above it at <= 5 %. With --pool the same statistics are averaged
over the seeds (pooled_passes: the run-averaged ratio's mean over the seeds in [0.8, 1.25], the mean fraction of
epochs inside the band >= 90 % and above it <= 5 %; a consistent filter gives 1, 0.95 and 0.025 whatever a state's
time correlation), with how many seeds pass the per-seed acceptance and how many a consistent filter would
(seed_pass_chance): the criterion a state with about one degree of freedom per run can meet.

--pool runs PROFILE at each of --seeds (each seed its own truth flight and RUNS sensor draws) and prints, per state,
what one seed's 95 % check cannot say (pool_seeds): the mean of the seeds' run-averaged ratios with its standard
error, the seeds' spread against the spread of chi2(R dof) / (R dof) sampling, the 95 % interval at the pooled dof,
how many seeds fall outside it (a consistent filter: 5 % of them, binomial tail given) and a Kolmogorov-Smirnov test
of the seeds' chi2 probabilities against the uniform distribution a consistent filter gives them.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import tomllib
from pathlib import Path
from types import MappingProxyType

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.stats import chi2  # noqa: E402

STATES = ("dp_N", "dp_E", "dp_D", "dv_N", "dv_E", "dv_D", "psi_N", "psi_E", "psi_D")


def _set(data: dict, item: str) -> None:
    """Apply one KEY=VALUE (dotted key, TOML value) to the profile's data."""
    key, _, value = item.partition("=")
    *path, last = key.split(".")
    node = data
    for k in path:
        node = node.setdefault(k, {})
    node[last] = tomllib.loads(f"v = {value}")["v"]


def flown(profile: Path, runs: int, seed: int, sets: tuple[str, ...] = (), slow_tau_s: float | None = None,
          ideal_imu_axes: str = "") -> tuple:
    """(profile, truth, records, start states, runs): the profile (with `sets`) flown once (seed, run 0) and RUNS sensor
    realizations on its truth (the truth options: module docstring)."""
    from approachsim.flight.run import Approach
    from approachsim.profile import parse_profile
    from approachsim.sensors.gnss import receiver
    from approachsim.sensors.states import start_states
    from approachsim.sensors.suite import SensorSuite

    data = tomllib.loads(profile.read_text(encoding="utf-8"))
    for item in sets:
        _set(data, item)
    prof = parse_profile(data, source=profile.resolve())
    truth = Approach(prof).fly(seed=seed, run=0).truth
    suite = SensorSuite.from_profile(prof)
    if slow_tau_s is not None:  # the truth's slow range errors only; the filter is built from the profile
        gnss = suite.sensors["gnss"]
        if not isinstance(gnss, receiver.GnssReceiver):
            raise SystemExit("--slow-tau-s needs a plain GNSS receiver (no fault on it)")
        budget = dataclasses.replace(gnss.budget, clock_ephemeris_tau_s=slow_tau_s, iono_tau_s=slow_tau_s,
                                     tropo_tau_s=slow_tau_s)
        suite = dataclasses.replace(suite, sensors=MappingProxyType(dict(suite.sensors) | {
            "gnss": dataclasses.replace(gnss, budget=budget)}))
    if ideal_imu_axes:  # the truth's IMU only; the filter is built from the profile's grade
        imu = suite.sensors["imu"]
        zero = {"gyro": ("gyro_sf", "gyro_misalign_rad"), "accel": ("accel_sf", "accel_misalign_rad")}
        grade = dataclasses.replace(imu.grade, **{k: 0.0 for s in ideal_imu_axes.split(",") for k in zero[s]})
        suite = dataclasses.replace(suite, sensors=MappingProxyType(dict(suite.sensors) | {
            "imu": dataclasses.replace(imu, grade=grade)}))
    errors = suite.draw(truth.t_s, seed, list(range(runs)))
    recs, st = suite.apply(truth, errors), start_states(suite, truth, errors, 0)
    zen = {}  # the zenith states' truth per sample: the service's common iono field part, its tropo zenith residual
    gnss = suite.sensors.get("gnss")
    sv = getattr(getattr(gnss, "budget", None), "service", None)
    if sv is not None:
        e = errors.sensors["gnss"]
        if sv.iono_zenith_state:
            zen["giz"] = (np.asarray(e.t_s), gnss.iono_zenith_error({"iono_field": np.asarray(e.series["iono_field"])}))
        if sv.tropo_zenith_state:
            zen["gtz"] = (np.asarray(e.t_s), gnss.tropo_zenith_error({"tropo": np.asarray(e.series["tropo"])}))
    return prof, truth, recs, st, runs, zen


def navigate(fl: tuple, seed: int, filter_turbulence: str | None = None
             ) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Open-loop navigation runs (shared covariance) on flown(...)'s records: (e (runs, epochs, s) the true errors,
    P (runs, epochs, s) the filter's variances, the state names) of the 9 navigation errors and, with GNSS, the
    receiver clock bias (m). filter_turbulence: the filter's gyro axis noise at that level (None: the profile's)."""
    from approachsim.nav.system import NavSystem
    from approachsim.seeding import stream

    prof, truth, recs, st, runs, zen = fl
    nav = NavSystem.from_profile(prof)
    if filter_turbulence is not None:
        nav = dataclasses.replace(nav, turbulence=filter_turbulence)
    rs = nav.run(truth, recs, [stream(seed, r, "nav") for r in range(runs)], shared_covariance=True, states=st)
    e = np.stack([r.true_error_nav for r in rs])
    d = np.diagonal(np.stack([r.P_nav for r in rs]), axis1=2, axis2=3)
    lay = rs[0].layout
    names = STATES
    if lay.has("clk") and "gnss" in recs:  # the receiver clock bias: the filter's clk state against the truth's
        g = recs["gnss"]
        t_g, cb = np.asarray(g.t_s), np.asarray(g.clock_bias_m).reshape(runs, -1)
        ic = lay.i("clk")
        idx = [np.clip(np.searchsorted(t_g, r.t_epoch_s + 1e-9, side="right") - 1, 0, t_g.size - 1) for r in rs]
        ec = np.stack([r.x[:, ic] - cb[i, j] for i, (r, j) in enumerate(zip(rs, idx, strict=True))])
        e = np.concatenate([e, ec[..., None]], axis=-1)
        d = np.concatenate([d, np.stack([r.P_diag[:, ic] for r in rs])[..., None]], axis=-1)
        names = names + ("clk",)
    for g, (t_g, z) in zen.items():  # the zenith states against the truth's iono field / tropo zenith residual
        if not lay.has(g):
            continue
        z = z.reshape(runs, t_g.size, -1)
        idx = [np.clip(np.searchsorted(t_g, r.t_epoch_s + 1e-9, side="right") - 1, 0, t_g.size - 1) for r in rs]
        for k, nm in enumerate(ZENITH_NAMES[g]):
            iz = lay.i(g, k)
            ez = np.stack([r.x[:, iz] - z[i, j, k] for i, (r, j) in enumerate(zip(rs, idx, strict=True))])
            e = np.concatenate([e, ez[..., None]], axis=-1)
            d = np.concatenate([d, np.stack([r.P_diag[:, iz] for r in rs])[..., None]], axis=-1)
            names = names + (nm,)
    return e, d, names


ZENITH_NAMES = {"giz": ("giz_0", "giz_E", "giz_N"), "gtz": ("gtz",)}
"""The zenith states' printed names: the iono field's common part, east and north gradient; the tropo residual."""


def summary(e: np.ndarray, d: np.ndarray) -> dict[str, np.ndarray]:
    """Per state over the approach after its first quarter: the run-averaged e^2 / P (mean over epochs), the
    fractions of epochs whose run average is inside / below / above the two-sided 95 % chi2(R)/R bounds (R runs),
    the filter's mean sigma and the run-mean error over the sigma's RMS (a deterministic error common to the runs
    on their one truth); dof, each run's time-averaged e^2 / P's chi2 degrees of freedom (2 mean^2 / variance over
    the runs: about 1 for a state whose error hardly changes over the approach, many for a fast one) and ratio_lo /
    ratio_hi, the 95 % sampling interval of the run-averaged ratio they give for a consistent filter (chi2(R dof) /
    (R dof)): how far one seed's ratio may fall from 1 by chance."""
    runs = e.shape[0]
    z = (e**2 / d).mean(axis=0)
    later = slice(z.shape[0] // 4, z.shape[0])
    lo, hi = chi2.ppf([0.025, 0.975], runs) / runs
    zc = z[later]
    sig = np.sqrt(d[:, later])
    zr = (e[:, later] ** 2 / d[:, later]).mean(axis=1)  # each run's own time-averaged e^2 / P
    dof = 2.0 * zr.mean(axis=0) ** 2 / np.maximum(zr.var(axis=0), 1e-300)  # its chi2 degrees of freedom per run
    return {"ratio": zc.mean(axis=0), "inside": np.mean((zc >= lo) & (zc <= hi), axis=0),
            "below": np.mean(zc < lo, axis=0), "above": np.mean(zc > hi, axis=0), "sigma": sig.mean(axis=(0, 1)),
            "common": np.sqrt(np.mean((e[:, later].mean(axis=0) / sig.mean(axis=0)) ** 2, axis=0)),
            "dof": dof, "ratio_lo": chi2.ppf(0.025, runs * dof) / (runs * dof),
            "ratio_hi": chi2.ppf(0.975, runs * dof) / (runs * dof),
            "bounds": np.array([lo, hi]), "epochs": np.array([z.shape[0], later.start])}


def pool_seeds(ratio: np.ndarray, dof: np.ndarray, runs: int) -> dict[str, np.ndarray]:
    """Per state (columns) over seeds (rows) of run-averaged ratios `ratio` (S, n) with their measured degrees of
    freedom per run `dof` (S, n), RUNS runs each: mean and its standard error; the seeds' sd and the sd a consistent
    filter's sampling gives, sqrt(2 / (R d)), d the seeds' mean dof; the 95 % interval of chi2(R d) / (R d); the
    number of seeds outside it and the binomial probability of at least that many when each is outside with
    probability 0.05; the Kolmogorov-Smirnov p-value of the seeds' chi2(R d) cdf values against the uniform."""
    from scipy.stats import binom, kstest

    r, d = np.atleast_2d(ratio), np.atleast_2d(dof)
    s = r.shape[0]
    n = runs * d.mean(axis=0)
    lo, hi = chi2.ppf(0.025, n) / n, chi2.ppf(0.975, n) / n
    outside = np.sum((r < lo) | (r > hi), axis=0)
    u = chi2.cdf(r * n, n)
    return {"mean": r.mean(axis=0), "se": r.std(axis=0, ddof=1) / np.sqrt(s), "sd": r.std(axis=0, ddof=1),
            "sd_expected": np.sqrt(2.0 / n), "dof": d.mean(axis=0), "lo": lo, "hi": hi, "outside": outside,
            "p_outside": binom.sf(outside - 1, s, 0.05),
            "ks_p": np.array([kstest(u[:, c], "uniform").pvalue for c in range(r.shape[1])]),
            "min": r.min(axis=0), "max": r.max(axis=0), "seeds": np.array(s)}


def _seed_summary(profile: Path, runs: int, seed: int, sets: tuple[str, ...], truth_kw: dict | None = None,
                  filter_turbulence: str | None = None) -> tuple[dict, tuple[str, ...]]:
    """summary() of PROFILE flown at one seed (truth_kw: flown()'s truth options; filter_turbulence: navigate()'s),
    and the state names."""
    e, d, names = navigate(flown(profile, runs, seed, sets, **(truth_kw or {})), seed, filter_turbulence)
    return summary(e, d), names


def run_pool(profile: Path, runs: int, seeds: list[int], sets: tuple[str, ...], workers: int,
             truth_kw: dict | None = None, filter_turbulence: str | None = None) -> None:
    """PROFILE at every seed (in `workers` processes); per state the seeds' ratios and pool_seeds printed (truth_kw,
    filter_turbulence: _seed_summary's)."""
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=workers) as ex:
        res = [f.result() for f in [ex.submit(_seed_summary, profile, runs, s, sets, truth_kw, filter_turbulence)
                                    for s in seeds]]
    names = res[0][1]
    ratio = np.array([r[0]["ratio"] for r in res])
    p = pool_seeds(ratio, np.array([r[0]["dof"] for r in res]), runs)
    print(f"{profile}: {len(seeds)} seeds x {runs} runs" + "".join(f"; {x}" for x in sets)
          + "".join(f"; truth {k} {v}" for k, v in (truth_kw or {}).items() if v)
          + (f"; filter turbulence {filter_turbulence}" if filter_turbulence else ""))
    print(f"  {'state':6s} {'mean':>6s} {'se':>6s} {'sd':>6s} {'sd exp':>6s} {'dof':>5s} {'95 % of a seed':>14s} "
          f"{'outside':>8s} {'P(>=)':>6s} {'KS p':>5s} {'min':>5s} {'max':>5s}")
    for c, nm in enumerate(names):
        print(f"  {nm:6s} {p['mean'][c]:6.3f} {p['se'][c]:6.3f} {p['sd'][c]:6.3f} {p['sd_expected'][c]:6.3f} "
              f"{p['dof'][c]:5.2f} [{p['lo'][c]:5.2f}, {p['hi'][c]:5.2f}] {p['outside'][c]:4d}/{len(seeds):<3d} "
              f"{p['p_outside'][c]:6.2f} {p['ks_p'][c]:5.2f} {p['min'][c]:5.2f} {p['max'][c]:5.2f}")
    print("  per seed: " + "; ".join(f"s{s} " + " ".join(f"{nm} {ratio[i, c]:.2f}" for c, nm in enumerate(names)
                                                      if nm in ("dp_N", "dp_E", "dp_D", "clk"))
                                     for i, s in enumerate(seeds)))


ROOT = Path(__file__).resolve().parents[1]
SUITE: dict[str, tuple[str, tuple[str, ...]]] = {
    "default": ("profiles/default.toml", ()),
    "CAT III candidate": ("profiles/gbas-cat3-candidate.toml", ()),
    "ISA -30, uncorrected": ("profiles/default.toml", ("environment.isa_dev_C=-30.0",)),
    "ISA +30, uncorrected": ("profiles/default.toml", ("environment.isa_dev_C=30.0",)),
    "5434 ft field": ("profiles/default.toml", ("runway.elevation_ft=5434.0",)),
}
"""The suite's cases: (profile, --set items)."""
CONTROL = "none"
"""The control filter: the drift-matched slow range-error tau alone, no gyro scale-factor / misalignment noise."""
RATIO_BAND = (0.8, 1.25)
INSIDE_MIN = 0.9
ABOVE_MAX = 0.05


def suite_case(case: str, seed: int, runs: int) -> dict[str, dict[str, list[float]]]:
    """One case at one seed: {"filter": summary, "control": summary} (arrays as lists), the two filters on the same
    flight and sensor records."""
    path, sets = SUITE[case]
    fl = flown(ROOT / path, runs, seed, sets)
    out = {}
    for name, turb in (("filter", None), ("control", CONTROL)):
        e, d, names = navigate(fl, seed, turb)
        out[name] = {k: np.asarray(v).tolist() for k, v in summary(e, d).items()} | {"names": list(names)}
    return out


def passes(sm: dict, c: int) -> bool:
    """Issue 39's acceptance for state c of a summary."""
    return (RATIO_BAND[0] <= sm["ratio"][c] <= RATIO_BAND[1] and sm["inside"][c] >= INSIDE_MIN
            and sm["above"][c] <= ABOVE_MAX)


def suite_table(results: dict[tuple[str, int], dict], runs: int, seeds: list[int]) -> str:
    """The markdown table of the suite (one block per case: per state, per seed, filter and control)."""
    lines = []
    for case, (path, sets) in SUITE.items():
        res = [results[(case, s)] for s in seeds]
        names = res[0]["filter"]["names"]
        lo, hi = res[0]["filter"]["bounds"]
        lines += [f"### {case}", "", f"`{path}`" + "".join(f" `--set {x}`" for x in sets)
                  + f"; {runs} runs per seed, 95 % band of the run average [{lo:.2f}, {hi:.2f}]; e^2/P, inside, "
                  "above per seed (s1 / s2 ...); pass: e^2/P in [0.8, 1.25], inside >= 0.90, above <= 0.05 at every "
                  "seed.", "",
                  "| state | filter e^2/P | inside | above | pass | control e^2/P | inside | above | pass |",
                  "|---|---|---|---|---|---|---|---|---|"]
        for c, n in enumerate(names):
            row = [n]
            for f in ("filter", "control"):
                row += [" / ".join(f"{r[f][k][c]:.2f}" for r in res) for k in ("ratio", "inside", "above")]
                row.append("yes" if all(passes(r[f], c) for r in res) else "**no**")
            lines.append("| " + " | ".join(row) + " |")
        ok = {f: all(passes(r[f], c) for r in res for c in range(len(names))) for f in ("filter", "control")}
        lines += ["", f"Acceptance met by every state: filter {'yes' if ok['filter'] else '**no**'}, control "
                  f"{'yes' if ok['control'] else 'no'}.", ""]
    return "\n".join(lines)


def seed_pass_chance(dof: float, runs: int) -> float:
    """The probability that a consistent filter's run-averaged ratio at one seed lies in RATIO_BAND: chi2(n) / n with
    n = runs dof degrees of freedom (summary()'s dof per run)."""
    n = runs * dof
    return float(chi2.cdf(RATIO_BAND[1] * n, n) - chi2.cdf(RATIO_BAND[0] * n, n))


def pooled(res: list[dict], c: int) -> dict[str, float]:
    """State c of one filter's summaries at S seeds: the mean ratio and its standard error, the mean fractions of
    epochs inside / above the band, the seeds' min and max ratio, the seeds passing the per-seed acceptance and the
    seeds' mean dof per run (for seed_pass_chance)."""
    r = np.array([x["ratio"][c] for x in res])
    dof = float(np.mean([x["dof"][c] for x in res]))
    return {"mean": float(r.mean()), "se": float(r.std(ddof=1) / np.sqrt(r.size)) if r.size > 1 else float("nan"),
            "inside": float(np.mean([x["inside"][c] for x in res])),
            "above": float(np.mean([x["above"][c] for x in res])), "min": float(r.min()), "max": float(r.max()),
            "seeds_pass": int(sum(passes(x, c) for x in res)), "dof": dof}


def pooled_passes(pc: dict[str, float]) -> bool:
    """Issue 39's acceptance on the seeds' averages (pooled())."""
    return (RATIO_BAND[0] <= pc["mean"] <= RATIO_BAND[1] and pc["inside"] >= INSIDE_MIN
            and pc["above"] <= ABOVE_MAX)


def pooled_table(results: dict[tuple[str, int], dict], runs: int, seeds: list[int]) -> str:
    """The markdown table of the pooled suite (one block per case: per state, filter and control, averaged over the
    seeds)."""
    lines = []
    for case, (path, sets) in SUITE.items():
        res = {f: [results[(case, s)][f] for s in seeds] for f in ("filter", "control")}
        names = res["filter"][0]["names"]
        lines += [f"### {case} (pooled)", "", f"`{path}`" + "".join(f" `--set {x}`" for x in sets)
                  + f"; {len(seeds)} seeds x {runs} runs; per state the seeds' mean e^2/P +- its standard error, "
                  "the mean fractions of epochs inside / above each seed's 95 % band, the seeds' range, the seeds "
                  "passing the per-seed acceptance against the number a consistent filter passes on average "
                  "(its ratio alone in [0.8, 1.25]: chi2 at the measured dof per run); pass: mean e^2/P in [0.8, "
                  "1.25], mean inside >= 0.90, mean above <= 0.05.", "",
                  "| state | filter e^2/P | inside | above | seeds' range | seeds passing (consistent) | pass | "
                  "control e^2/P | inside | above | pass |",
                  "|---|---|---|---|---|---|---|---|---|---|---|"]
        ok = {"filter": True, "control": True}
        for c, n in enumerate(names):
            pf, pk = pooled(res["filter"], c), pooled(res["control"], c)
            chance = seed_pass_chance(pf["dof"], runs) * len(seeds)
            ok["filter"] &= pooled_passes(pf)
            ok["control"] &= pooled_passes(pk)
            lines.append(f"| {n} | {pf['mean']:.3f} +- {pf['se']:.3f} | {pf['inside']:.2f} | {pf['above']:.2f} | "
                         f"{pf['min']:.2f}-{pf['max']:.2f} | {pf['seeds_pass']}/{len(seeds)} ({chance:.1f}) | "
                         f"{'yes' if pooled_passes(pf) else '**no**'} | {pk['mean']:.3f} +- {pk['se']:.3f} | "
                         f"{pk['inside']:.2f} | {pk['above']:.2f} | {'yes' if pooled_passes(pk) else '**no**'} |")
        lines += ["", f"Pooled acceptance met by every state: filter {'yes' if ok['filter'] else '**no**'}, control "
                  f"{'yes' if ok['control'] else 'no'}.", ""]
    return "\n".join(lines)


def run_suite(runs: int, seeds: list[int], workers: int, out: Path | None, pool: bool = False) -> None:
    """Every case of SUITE at every seed (in `workers` processes); the table (pool: pooled_table, under POOL_MARK)
    printed and written to `out`."""
    from concurrent.futures import ProcessPoolExecutor

    jobs = [(c, s) for c in SUITE for s in seeds]
    with ProcessPoolExecutor(max_workers=workers) as ex:
        futs = {j: ex.submit(suite_case, j[0], j[1], runs) for j in jobs}
        results = {j: f.result() for j, f in futs.items()}
    table = pooled_table(results, runs, seeds) if pool else suite_table(results, runs, seeds)
    print(table)
    if out is not None:
        text = out.read_text(encoding="utf-8") if out.exists() else ""
        out.write_text(with_table(text, POOL_MARK if pool else TABLE_MARK, table), encoding="utf-8")
        js = json.dumps({f"{c} / seed {s}": r for (c, s), r in results.items()}, indent=1)
        out.with_name(out.stem + ("-pooled" if pool else "") + ".json").write_text(js, encoding="utf-8")


TABLE_MARK = "<!-- consistency suite table: tools/consistency_by_state.py --suite writes below -->"
POOL_MARK = "<!-- pooled consistency suite table: tools/consistency_by_state.py --suite --pool writes below -->"
END_MARK = "<!-- end of table -->"


def with_table(text: str, mark: str, table: str) -> str:
    """text with the table after `mark` replaced by `table`: up to the next END_MARK (to the end of the text when
    none follows), the mark and table appended when the text has no mark."""
    block = mark + "\n\n" + table.rstrip("\n") + "\n\n" + END_MARK + "\n"
    if mark not in text:
        return text.rstrip("\n") + "\n\n" + block
    head, _, rest = text.partition(mark)
    _, found, tail = rest.partition(END_MARK)
    return head + block + (tail.lstrip("\n") and "\n" + tail.lstrip("\n") if found else "")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profile", type=Path, nargs="?")
    ap.add_argument("--suite", action="store_true")
    ap.add_argument("--pool", action="store_true", help="PROFILE (or with --suite every case) at each of --seeds, "
                    "pooled (module docstring)")
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--runs", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--slow-tau-s", type=float, default=None)
    ap.add_argument("--ideal-imu-axes", default="", choices=("", "gyro", "accel", "gyro,accel"),
                    help="the truth's IMU without scale-factor and misalignment errors (gyro, accel or both)")
    ap.add_argument("--filter-turbulence", default=None, choices=("none", "light", "moderate", "severe"),
                    help="the filter's gyro axis process noise at this turbulence level (default: the profile's)")
    a = ap.parse_args()
    if a.suite:
        run_suite(a.runs, a.seeds, a.workers, a.out, a.pool)
        return
    if a.profile is None:
        ap.error("PROFILE is required without --suite")
    if a.pool:
        run_pool(a.profile, a.runs, a.seeds, tuple(a.set), a.workers,
                 {"slow_tau_s": a.slow_tau_s, "ideal_imu_axes": a.ideal_imu_axes}, a.filter_turbulence)
        return
    fl = flown(a.profile, a.runs, a.seed, tuple(a.set), a.slow_tau_s, a.ideal_imu_axes)
    e, d, names = navigate(fl, a.seed, a.filter_turbulence)
    s = summary(e, d)
    lo, hi = s["bounds"]
    print(f"{a.profile}: {a.runs} runs, {s['epochs'][0]} epochs (from epoch {s['epochs'][1]}); 95 % bounds "
          f"[{lo:.2f}, {hi:.2f}]" + "".join(f"; {x}" for x in a.set)
          + (f"; truth slow taus {a.slow_tau_s:g} s" if a.slow_tau_s is not None else "")
          + (f"; truth {a.ideal_imu_axes} without scale factor / misalignment" if a.ideal_imu_axes else "")
          + (f"; filter turbulence {a.filter_turbulence}" if a.filter_turbulence else ""))
    print(f"  {'state':6s} {'e^2/P':>6s} {'inside':>7s} {'below':>6s} {'above':>6s} {'sigma':>10s} {'common':>7s} "
          f"{'dof/run':>7s} {'ratio 95 %':>12s}")
    for c, name in enumerate(names):
        print(f"  {name:6s} {s['ratio'][c]:6.2f} {s['inside'][c]:7.2f} {s['below'][c]:6.2f} {s['above'][c]:6.2f} "
              f"{s['sigma'][c]:10.3g} {s['common'][c]:7.2f} {s['dof'][c]:7.2f} "
              f"[{s['ratio_lo'][c]:.2f}, {s['ratio_hi'][c]:.2f}]")

if __name__ == "__main__":
    main()
