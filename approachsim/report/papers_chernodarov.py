"""Figures of the Chernodarov reproduction in the style of the paper's Figs. 1, 2 and 4, plus the NEES check.

Fig. 1: influence functions psi(beta) and psi'(beta); Fig. 2: the primary channel's signal (light) and the
robust filter's estimate (dark), with the monitor's decisions; Fig. 4: drift and its estimate (deg/h);
NEES: average NEES over runs against its 95 % chi^2 bounds, plain EKF vs robust U-D.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from approachsim.nav import monitors as mon
from approachsim.nav.ud import INFLUENCES, InfluenceFunction
from approachsim.papers.chernodarov import nees_bounds

_RAD_S_TO_DEG_H = 180.0 / np.pi * 3600.0
_RAD_TO_ARCSEC = 180.0 / np.pi * 3600.0


def write_figures(s: Any, results: dict[str, Any], p: Any, out_dir: Path) -> list[str]:
    """Write chernodarov_fig{1,2,4}.png and chernodarov_nees.png; return the file names."""
    out_dir = Path(out_dir)
    names = []

    beta = np.linspace(-6, 6, 1201)
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for kind in INFLUENCES:
        psi, dpsi = InfluenceFunction(kind).arrays(beta, beta)  # type: ignore[arg-type]
        axes[0].plot(beta, psi, lw=1.2, label=kind)
        axes[1].plot(beta, dpsi, lw=1.2, label=kind)
    axes[0].set_ylabel("psi(beta)")
    axes[1].set_ylabel("psi'(beta)")
    for ax in axes:
        ax.set_xlabel("beta (sigma)")
        ax.axvline(3, color="0.6", lw=0.6, ls=":")
        ax.axvline(-3, color="0.6", lw=0.6, ls=":")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Fig. 1 (ours): influence functions and their derivatives")
    fig.tight_layout()
    fig.savefig(out_dir / "chernodarov_fig1.png", dpi=110)
    plt.close(fig)
    names.append("chernodarov_fig1.png")

    robust = results["robust-ud-gauss-laplace"]
    run = 0
    t = s.t_s
    fig, ax = plt.subplots(figsize=(8, 3.8))
    ax.plot(t, s.z_primary[run] * _RAD_TO_ARCSEC, color="0.75", lw=0.8, label="primary channel observation")
    ax.plot(t, robust.x_hat[run, :, 0] * _RAD_TO_ARCSEC, color="k", lw=1.2, label="robust U-D estimate")
    out = robust.decision[run] == mon.OUTLIER
    ax.plot(t[out], s.z_primary[run, out] * _RAD_TO_ARCSEC, "rx", ms=6, label="flagged outlier")
    ax.axvline(s.onset_s[run], color="tab:orange", ls="--", lw=1, label="ramp failure onset")
    if np.isfinite(robust.switch_s[run]):
        ax.axvline(robust.switch_s[run], color="tab:red", lw=1, label="failure detected: twin connected")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("angle error (arcsec)")
    ax.set_title("Fig. 2 (ours): primary channel signal, robust estimate and decisions (run 0)")
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out_dir / "chernodarov_fig2.png", dpi=110)
    plt.close(fig)
    names.append("chernodarov_fig2.png")

    fig, ax = plt.subplots(figsize=(8, 3.6))
    ax.plot(t, s.x_true[run, :, 1] * _RAD_S_TO_DEG_H, color="0.6", lw=2, label="actual drift")
    ax.plot(t, results["ekf"].x_hat[run, :, 1] * _RAD_S_TO_DEG_H, color="tab:blue", lw=1, label="EKF estimate")
    ax.plot(t, robust.x_hat[run, :, 1] * _RAD_S_TO_DEG_H, color="k", lw=1, label="robust U-D estimate")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("drift (deg/h)")
    ax.set_title("Fig. 4 (ours): FOG drift and its estimate (run 0)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out_dir / "chernodarov_fig4.png", dpi=110)
    plt.close(fig)
    names.append("chernodarov_fig4.png")

    lo, hi = nees_bounds(s.z_primary.shape[0])
    fig, ax = plt.subplots(figsize=(8, 3.6))
    for name, color in (("ekf", "tab:blue"), ("robust-ud-gauss-laplace", "k"), ("robust-ud-laplace", "tab:green")):
        ax.semilogy(t, results[name].nees.mean(axis=0), color=color, lw=1, label=name)
    ax.axhspan(lo, hi, color="tab:green", alpha=0.15, label="95 % chi^2 bounds")
    ax.axvspan(*p.fail_onset_s, color="tab:orange", alpha=0.1, label="failure onsets")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("average NEES")
    ax.set_title("Average NEES over the runs")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out_dir / "chernodarov_nees.png", dpi=110)
    plt.close(fig)
    names.append("chernodarov_nees.png")
    return names
