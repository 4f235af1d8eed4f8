"""Issue 26 acceptance, estimator validation: the same fault mode and the same event by brute force (plain Monte
Carlo over the fault distribution, plain numpy normals) and by importance sampling (NAIS, integrity.rare), on the
real simulation.

    PYTHONPATH=. python benchmarks/rare_event_validation.py [--profile P] [--mode baro-step-halfnormal]
        [--thresholds C1,C2] [--brute N] [--samples N] [--seed S] [--workers K] [--truths T] [--pilot N]
        [--vmax-file F] [--no-nais] [--method nais|ce] [--strata E1,E2 --strata-samples N] [--out FILE.json]

The event: the protected output's largest vertical error over the CAT I window (campaign.integrity_risk.limit_states
`cat1_vmax_m`: the main solution, after an exclusion the excluded sub-solution) exceeds C metres, given one fault of
the mode with its parameters drawn from the mode's distribution. The default mode
(campaign.integrity_risk.VALIDATION_MODES) is a baro step of 5 m |u| (half-normal) at a uniform onset: the GPS-only
bank cannot see it, so the error's tail is the step's own and importance sampling over u has something to find. (A
satellite ramp with the same event does not: its largest vertical error is the nominal noise's, rank correlation
0.04 with the ramp's rate over 1500 runs, and NAIS had not reached 2.9 m after about 1300 runs: IS over the fault
parameters only helps where the event is driven by them.) The levels C are where brute force can answer (about 1e-2
and 1e-3 here); --pilot N runs N plain samples on other run indices first and prints the quantiles to choose them
(neither the brute-force nor the IS samples see the pilot). Brute force (plain numpy normals through the same map)
runs once and its values are compared with every C; they are appended to --vmax-file as chunks finish, so a
brute-force-only run (--no-nais) and a NAIS-only run (--brute 0 with the same --vmax-file, read at the end) can go
side by side. NAIS runs once per C, each on its own run indices (its own noise) and its own OpenTURNS seed. Prints
and writes the table: estimate, CoV, one-sided bounds, hits, evaluations, wall time, whether the intervals overlap.

--strata E1,E2,...: a second reference, stratified plain Monte Carlo over the magnitude input |u_1| (Cochran,
*Sampling techniques*, ch. 5): strata [E1, E2), ..., [Ek, inf) of known probability P_j = 2 (Phi(E_j+1) -
Phi(E_j)), each with --strata-samples plain samples of the conditional law (|u_1| by the inverse CDF within the
stratum, its sign and the other inputs as drawn), on their own run indices; the stratum below E1 is read from the
brute force's own samples there (its u re-drawn from the same generator). The estimate p = sum_j P_j k_j / n_j,
Var = sum_j P_j^2 p_j (1 - p_j) / n_j, one-sided normal bounds at 0.95: no adaptation, no likelihood ratio, so it
checks the estimators where the brute force's hits are too few (the tail lives in the upper strata).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy import stats as sps

from approachsim.campaign.integrity_risk import MODES, VALIDATION_MODES, Simulator, _columns, fault_mode
from approachsim.integrity import rare
from approachsim.profile import load_profile


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--profile", type=Path, default=Path(__file__).resolve().parents[1] / "profiles/default.toml")
    ap.add_argument("--mode", default="baro-step-halfnormal", choices=sorted({**MODES, **VALIDATION_MODES}))
    ap.add_argument("--thresholds", default=None, help="comma-separated levels C, m")
    ap.add_argument("--brute", type=int, default=5000)
    ap.add_argument("--samples", type=int, default=200, help="NAIS samples per step")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--truths", type=int, default=4)
    ap.add_argument("--pilot", type=int, default=0)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--vmax-file", type=Path, default=Path("rare_event_validation_vmax.txt"),
                    help="brute-force values, appended as they finish (and read back: a run can be continued)")
    ap.add_argument("--brute-wall-s", type=float, default=None, help="wall time of an earlier brute-force run, s")
    ap.add_argument("--no-nais", action="store_true", help="brute force only")
    ap.add_argument("--method", default="nais", choices=("nais", "ce"),
                    help="the importance-sampling estimator (integrity.rare.estimate): NAIS or cross-entropy")
    ap.add_argument("--level-offset", type=int, default=0,
                    help="NAIS run indices and seeds as if the levels came after this many others (a later run's "
                         "levels stay independent of an earlier one's)")
    ap.add_argument("--strata", default=None, help="comma-separated |u_1| edges of the stratified reference")
    ap.add_argument("--strata-samples", type=int, default=3000, help="plain samples per stratum")
    a = ap.parse_args()
    profile = load_profile(a.profile)
    mode = fault_mode(a.mode)
    res: dict = {"profile": profile.name, "mode": a.mode, "seed": a.seed, "truths": a.truths, "levels": []}
    t_all = time.time()
    with Simulator(profile, a.seed, a.truths, a.workers) as sim:
        if a.pilot:
            t = time.time()
            rng = np.random.default_rng(a.seed + 12345)
            rows = sim.run(a.mode, 9_000_000 + np.arange(a.pilot), rng.standard_normal((a.pilot, mode.dim)))
            v = np.sort(_columns(rows)["cat1_vmax_m"])[::-1]
            print(f"pilot {a.pilot} samples ({time.time() - t:.0f} s): largest vmax (m)", np.round(v[:12], 2),
                  "quantiles 0.9/0.99:", np.round(np.quantile(v, [0.9, 0.99]), 2), flush=True)
        if a.thresholds is None:
            return
        levels = [float(x) for x in a.thresholds.split(",")]
        counter = [0]

        def sample(u: np.ndarray, base: int) -> np.ndarray:
            runs = base + counter[0] + np.arange(u.shape[0])
            counter[0] += u.shape[0]
            cols = _columns(sim.run(a.mode, runs, u))
            return np.where(cols["failed"] > 0, 1e3, cols["cat1_vmax_m"])

        if a.brute:  # plain Monte Carlo over the fault distribution, in chunks appended to --vmax-file as they finish
            t = time.time()
            rng = np.random.default_rng(a.seed * 31)
            done = 0
            chunk = 50 * a.workers
            while done < a.brute:
                n = min(chunk, a.brute - done)
                u = rng.standard_normal((n, mode.dim))
                cols = _columns(sim.run(a.mode, 5_000_000 + done + np.arange(n), u))
                v = np.where(cols["failed"] > 0, 1e3, cols["cat1_vmax_m"])
                with open(a.vmax_file, "a") as fh:
                    np.savetxt(fh, v)
                done += n
                print(f"brute force {done}/{a.brute} ({time.time() - t:.0f} s); above the levels:",
                      [int(np.sum(np.loadtxt(a.vmax_file) > c)) for c in levels], flush=True)
        wall_mc = float(a.brute_wall_s) if a.brute_wall_s else (time.time() - t if a.brute else float("nan"))
        if a.strata:
            vmax = np.atleast_1d(np.loadtxt(a.vmax_file)) if a.vmax_file.exists() else np.empty(0)
            res["stratified"] = stratified(sim, a, mode.dim, [float(x) for x in a.strata.split(",")], levels, vmax)
        if a.no_nais:
            if a.out is not None:
                a.out.write_text(json.dumps(res, indent=1) + "\n")
            vmax = np.atleast_1d(np.loadtxt(a.vmax_file))
            for c in levels:
                k = int(np.sum(vmax > c))
                print(f"C = {c} m: brute force {k}/{vmax.size} = {k / vmax.size:.3g} "
                      f"{rare.clopper_pearson(k, vmax.size, 0.95)}")
            return
        nais_rows = []
        for j, c in enumerate(levels, start=a.level_offset):
            counter[0] = 0
            t = time.time()
            est, _ = rare.estimate(lambda u, c=c, j=j: sample(u, 6_000_000 + 100_000 * j) - c, mode.dim,
                                   method=a.method, samples=a.samples, seed=a.seed * 31 + 1 + j,
                                   max_calls=12 * a.samples)
            nais_rows.append({**est.as_dict(), "wall_s": time.time() - t})
            print(f"C = {c} m: {a.method.upper()} {est.probability:.3g} CoV {est.cov:.2g} "
                  f"[{est.lower:.3g}, {est.upper:.3g}] hits "
                  f"{est.hits}/{est.samples} calls {est.calls} ({est.steps} steps, {nais_rows[-1]['wall_s']:.0f} s) "
                  f"{est.note}", flush=True)
    vmax = np.atleast_1d(np.loadtxt(a.vmax_file)) if a.vmax_file.exists() else np.empty(0)
    res["brute_force"] = {"samples": int(vmax.size), "wall_s": wall_mc,
                          "largest_vmax_m": [float(x) for x in np.sort(vmax)[::-1][:20]]}
    for c, nais in zip(levels, nais_rows, strict=True):
        k = int(np.sum(vmax > c))
        lo, hi = rare.clopper_pearson(k, vmax.size, 0.95)
        mc = {"method": "mc", "probability": k / max(vmax.size, 1), "lower": lo, "upper": hi, "hits": k,
              "calls": int(vmax.size), "wall_s": wall_mc}
        overlap = bool(lo <= (nais["upper"] or 1.0) and (nais["lower"] or 0.0) <= hi)
        row = {"threshold_m": c, "brute_force": mc, "nais": nais, "overlap": overlap}
        extra = ""
        for st in res.get("stratified", {}).get("levels", []):
            if st["threshold_m"] == c:
                row["overlap_stratified"] = bool(st["lower"] <= (nais["upper"] or 1.0)
                                                 and (nais["lower"] or 0.0) <= st["upper"])
                extra = (f"; stratified {st['probability']:.3g} [{st['lower']:.3g}, {st['upper']:.3g}], overlap "
                         f"{row['overlap_stratified']}")
        res["levels"].append(row)
        print(f"C = {c} m: brute force {k}/{vmax.size} = {mc['probability']:.3g} [{lo:.3g}, {hi:.3g}]; NAIS "
              f"{nais['probability']} [{nais['lower']}, {nais['upper']}]; overlap {overlap}{extra}", flush=True)
    res["wall_s"] = time.time() - t_all
    if a.out is not None:
        a.out.write_text(json.dumps(res, indent=1) + "\n")


def stratified(sim: Simulator, a: argparse.Namespace, dim: int, edges: list[float], levels: list[float],
               vmax_brute: np.ndarray) -> dict:
    """The stratified reference (module docstring): each stratum's samples and, per level, the estimate."""
    rng = np.random.default_rng(777 * a.seed)
    bounds = list(zip(edges, edges[1:] + [np.inf], strict=True))
    strata = []
    for j, (lo, hi) in enumerate(bounds):
        t = time.time()
        n = a.strata_samples
        q = sps.norm.cdf(lo) + rng.random(n) * (sps.norm.cdf(hi) - sps.norm.cdf(lo))
        u = np.empty((n, dim))
        u[:, 1] = np.where(rng.random(n) < 0.5, -1.0, 1.0) * sps.norm.ppf(q)
        u[:, [i for i in range(dim) if i != 1]] = rng.standard_normal((n, dim - 1))
        cols = _columns(sim.run(a.mode, 8_000_000 + 100_000 * j + np.arange(n), u))
        v = np.where(cols["failed"] > 0, 1e3, cols["cat1_vmax_m"])
        strata.append({"u1_abs": [lo, hi], "p_stratum": float(2.0 * (sps.norm.cdf(hi) - sps.norm.cdf(lo))),
                       "samples": n, "vmax_m": v, "wall_s": time.time() - t})
        print(f"stratum |u_1| in [{lo}, {hi}): {n} samples ({strata[-1]['wall_s']:.0f} s), largest vmax "
              f"{v.max():.2f} m", flush=True)
    u_brute = np.random.default_rng(a.seed * 31).standard_normal((vmax_brute.size, dim))  # the brute force's u
    below = np.abs(u_brute[:, 1]) < edges[0]
    p_below = float(2.0 * sps.norm.cdf(edges[0]) - 1.0)
    z = float(sps.norm.ppf(0.95))
    out = {"strata": [{k: v for k, v in s.items() if k != "vmax_m"} for s in strata],
           "below": {"u1_abs": [0.0, edges[0]], "p_stratum": p_below, "samples": int(below.sum()),
                     "largest_vmax_m": float(vmax_brute[below].max()) if below.any() else None}, "levels": []}
    for c in levels:
        k0, n0 = int(np.sum(vmax_brute[below] > c)), int(below.sum())
        p = p_below * k0 / n0 if n0 else 0.0
        var = p_below**2 * (k0 / n0) * (1 - k0 / n0) / n0 if n0 else 0.0
        hits = []
        for s in strata:
            k = int(np.sum(s["vmax_m"] > c))
            pj = k / s["samples"]
            p += s["p_stratum"] * pj
            var += s["p_stratum"] ** 2 * pj * (1.0 - pj) / s["samples"]
            hits.append(k)
        sd = var**0.5
        row = {"threshold_m": c, "probability": p, "sd": sd, "lower": max(0.0, p - z * sd), "upper": p + z * sd,
               "hits": hits, "below_hits": k0, "below_upper_cp": p_below * rare.clopper_pearson(k0, n0, 0.95)[1]}
        out["levels"].append(row)
        print(f"C = {c} m: stratified {p:.3g} (sd {sd:.2g}) [{row['lower']:.3g}, {row['upper']:.3g}], hits per "
              f"stratum {hits}; below |u_1| {edges[0]}: {k0} of {n0} (largest {out['below']['largest_vmax_m']:.2f} m)",
              flush=True)
    return out


if __name__ == "__main__":
    main()
