"""Figures of the Hajiyev & Saltoglu reproduction, in the style of the paper's Figures 2-7.

Figure 2/4/6 style: INS altitude error (solid) against the integrated system error (dotted) over the
iterations, one realization (run 0) with the Monte Carlo RMS envelope of the integrated error. Figure 3/5/7
style: model dH_I (solid) and its estimate (dotted), their difference, and the filter's error variance.
Plus a figure the paper does not have: the distribution over runs of the error jump at the fault steps.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from approachsim.papers.hajiyev_saltoglu import Runs


def _ins_vs_integrated(path: Path, runs: Runs, est: np.ndarray, title: str) -> Path:
    k = np.arange(runs.dh_ins.shape[1])
    integ = runs.dh_ins - est
    fig = Figure(figsize=(7, 4))
    ax = fig.add_subplot()
    ax.plot(k, runs.dh_ins[0], "k-", label="INS error (run 0)")
    ax.plot(k, integ[0], "k:", label="integrated system error (run 0)")
    rms = np.sqrt(np.mean(integ**2, axis=0))
    ax.fill_between(k, -rms, rms, color="0.8", label="integrated error, Monte Carlo RMS")
    ax.set_xlabel("iteration")
    ax.set_ylabel("altitude error, m")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


def _model_vs_estimate(path: Path, runs: Runs, est: np.ndarray, sigma: np.ndarray, title: str) -> Path:
    k = np.arange(runs.dh_ins.shape[1])
    fig = Figure(figsize=(7, 6))
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    ax1.plot(k, runs.dh_ins[0], "k-", label="model dH_I")
    ax1.plot(k, est[0], "k:", label="estimate")
    ax1.set_ylabel("m")
    ax1.legend(fontsize=8)
    ax1.set_title(title)
    ax2.plot(k, runs.dh_ins[0] - est[0], "k-")
    ax2.set_ylabel("difference, m")
    ax3.semilogy(k, sigma[0] ** 2, "k-")
    ax3.set_ylabel("P(1,1), m^2")
    ax3.set_xlabel("iteration")
    for ax in (ax1, ax2, ax3):
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


def _jumps(path: Path, faulty: Runs, fault_steps: tuple[int, ...]) -> Path:
    fig = Figure(figsize=(7, 4))
    ax = fig.add_subplot()
    for est, label, style in ((faulty.est_okf, "OKF", "C3"), (faulty.est_rkf, "RKF", "C0")):
        err = faulty.dh_ins - est
        ratios = np.concatenate([np.abs(err[:, k]) / np.abs(err[:, k - 1]) for k in fault_steps])
        ax.hist(np.log10(ratios), bins=40, alpha=0.6, color=style, label=label)
    ax.axvline(np.log10(1.5), color="k", ls="--", label="1.5x")
    ax.set_xlabel("log10 |e(k)| / |e(k-1)| at the fault steps k")
    ax.set_ylabel("runs x fault steps")
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


def plot_all(out_dir: Path, clean: Runs, faulty: Runs, fault_steps: tuple[int, ...]) -> list[Path]:
    """Write the reproduction's figures as PNG files into out_dir; return their paths."""
    out_dir = Path(out_dir)
    stem = "hajiyev-saltoglu"
    return [
        _ins_vs_integrated(out_dir / f"{stem}_fig2_okf.png", clean, clean.est_okf, "OKF, no faults (cf. Fig. 2)"),
        _model_vs_estimate(
            out_dir / f"{stem}_fig3_okf.png", clean, clean.est_okf, clean.sigma_okf, "OKF, no faults (cf. Fig. 3)"
        ),
        _ins_vs_integrated(out_dir / f"{stem}_fig4_okf_faults.png", faulty, faulty.est_okf, "OKF, faults (cf. Fig. 4)"),
        _model_vs_estimate(
            out_dir / f"{stem}_fig5_okf_faults.png", faulty, faulty.est_okf, faulty.sigma_okf, "OKF, faults (Fig. 5)"
        ),
        _ins_vs_integrated(out_dir / f"{stem}_fig6_rkf_faults.png", faulty, faulty.est_rkf, "RKF, faults (cf. Fig. 6)"),
        _model_vs_estimate(
            out_dir / f"{stem}_fig7_rkf_faults.png", faulty, faulty.est_rkf, faulty.sigma_rkf, "RKF, faults (Fig. 7)"
        ),
        _jumps(out_dir / f"{stem}_fault_jumps.png", faulty, fault_steps),
    ]
