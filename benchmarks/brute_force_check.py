"""Checks of a brute-force reference that disagrees with an estimator (docs/integrity.md, "Toward 1e-4"): is the
brute force's count luck, or something systematic in its runs? And is NAIS biased on a limit state that is noisy
given u?

    PYTHONPATH=. python benchmarks/brute_force_check.py renoise --vmax-file F [--level 10.5] [--tail 2.8]
        [--bases 5100000,5200000,6500000,7100000,8500000]
    PYTHONPATH=. python benchmarks/brute_force_check.py surrogate --vmax-file F [--level 10.5] [--seeds 20]

renoise: the brute force's samples with |u_1| > tail (u re-drawn from its generator, as
benchmarks/rare_event_validation.py drew them) are run again at their own u on other run-index ranges (new sensor
and filter noise). Their original indices must reproduce each value exactly; the hits on new noise show what those
u give on average (the brute force's noise luck), and the same u's hit rate against the stratified reference's
says how lucky its u were.

surrogate: a noisy limit state fitted to the brute force's samples with steps above 8 m, vmax = c0 m + c1 m onset +
c2 m sign(u_1) + c3 + c4 onset + N(0, s^2) (m = 5 |u_1| the step, onset its fraction of the window), with its exact
exceedance probability by quadrature over u; NAIS (integrity.rare, 300 per step) on it over several seeds, noisy
and with the noise removed: mean estimate / exact and how many runs' 90 % intervals hold the exact value.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from scipy import stats as sps

from approachsim.campaign.integrity_risk import Simulator, _columns
from approachsim.integrity import rare

ROOT = Path(__file__).resolve().parents[1]
MODE = "baro-step-halfnormal"


def brute_u(vmax: np.ndarray, seed: int) -> np.ndarray:
    """The brute force's inputs: rare_event_validation draws them from default_rng(31 seed) in order."""
    return np.random.default_rng(seed * 31).standard_normal((vmax.size, 2))


def renoise(a: argparse.Namespace) -> None:
    from approachsim.profile import load_profile

    v = np.atleast_1d(np.loadtxt(a.vmax_file))
    u = brute_u(v, a.seed)
    idx = np.flatnonzero(np.abs(u[:, 1]) > a.tail)
    print(f"{idx.size} brute-force samples with |u_1| > {a.tail}: {int(np.sum(v[idx] > a.level))} above {a.level} m")
    with Simulator(load_profile(a.profile), a.seed, a.truths, a.workers) as sim:
        same = _columns(sim.run(MODE, 5_000_000 + idx, u[idx]))["cat1_vmax_m"]
        print(f"  their own run indices: largest |difference| {np.max(np.abs(same - v[idx])):.3g} m")
        hits = []
        for base in (int(b) for b in a.bases.split(",")):
            b = _columns(sim.run(MODE, base + np.arange(idx.size), u[idx]))["cat1_vmax_m"]
            hits.append(int(np.sum(b > a.level)))
            print(f"  new noise (indices from {base}): {hits[-1]} above {a.level} m, mean vmax "
                  f"{np.mean(b - v[idx]):+.3f} m from the originals", flush=True)
    print(f"  mean {np.mean(hits):.1f} hits on new noise against {int(np.sum(v[idx] > a.level))} in the brute force; "
          f"Poisson tail of the brute force's count at that mean: "
          f"{sps.poisson.sf(int(np.sum(v[idx] > a.level)) - 1, np.mean(hits)):.2g}")


def surrogate(a: argparse.Namespace) -> None:
    v = np.atleast_1d(np.loadtxt(a.vmax_file))
    u = brute_u(v, a.seed)

    def features(u: np.ndarray) -> np.ndarray:
        m, on = 5.0 * np.abs(u[:, 1]), sps.norm.cdf(u[:, 0])
        return np.c_[m, m * on, m * np.sign(u[:, 1]), np.ones(len(m)), on]

    big = 5.0 * np.abs(u[:, 1]) > 8.0
    coef, *_ = np.linalg.lstsq(features(u[big]), v[big], rcond=None)
    s = float(np.std(v[big] - features(u[big]) @ coef))
    print(f"surrogate from {int(big.sum())} samples: coefficients {np.round(coef, 3)}, residual sd {s:.3f} m")
    grid = np.linspace(-8.0, 8.0, 3201)
    g0, g1 = np.meshgrid(grid, grid, indexing="ij")
    ug = np.c_[g0.ravel(), g1.ravel()]
    dens = sps.norm.pdf(ug).prod(axis=1) * (grid[1] - grid[0]) ** 2
    f = features(ug) @ coef
    exact = {"noisy": float(np.sum(dens * sps.norm.sf((a.level - f) / s))),
             "noise removed": float(np.sum(dens * (f > a.level)))}
    for label, sd in (("noisy", s), ("noise removed", 0.0)):
        rng = np.random.default_rng(5)
        est, inside = [], 0
        for k in range(a.seeds):
            def g(x: np.ndarray, sd: float = sd, rng: np.random.Generator = rng) -> np.ndarray:
                return features(x) @ coef + sd * rng.standard_normal(x.shape[0]) - a.level

            e, _ = rare.estimate(g, 2, method="nais", samples=300, seed=100 + k, max_calls=3600)
            est.append(e.probability)
            inside += int(e.lower <= exact[label] <= e.upper)
        r = np.array(est) / exact[label]
        print(f"  {label}: exact {exact[label]:.3g}; NAIS over {a.seeds} seeds: mean / exact {np.nanmean(r):.2f}, "
              f"median {np.nanmedian(r):.2f}, {inside} of {a.seeds} within their 90 % interval")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("part", choices=["renoise", "surrogate"])
    ap.add_argument("--vmax-file", type=Path, required=True)
    ap.add_argument("--level", type=float, default=10.5)
    ap.add_argument("--tail", type=float, default=2.8)
    ap.add_argument("--bases", default="5100000,5200000,6500000,7100000,8500000")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--truths", type=int, default=4)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--profile", type=Path, default=ROOT / "profiles" / "default.toml")
    a = ap.parse_args()
    (renoise if a.part == "renoise" else surrogate)(a)


if __name__ == "__main__":
    main()
