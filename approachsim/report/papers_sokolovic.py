"""Figures of the Sokolovic, Dikic & Stancic reproduction in the style of the paper's Figs. 3, 5, 6 and 7.

Fig. 3: altitude profile and baro error; Figs. 5-7: rms (over the Monte Carlo runs) of the altitude and
velocity errors against time, constant vs tanh, constant vs sinh, tanh vs sinh; GPS gaps shaded.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from approachsim.papers.sokolovic import SokolovicParams, trajectory

_STYLE = {"constant": ("k", "-"), "tanh": ("tab:blue", "--"), "sinh": ("tab:red", "-")}


def _shade_gaps(ax: Any, t: np.ndarray, gps_on: np.ndarray) -> None:
    off = ~gps_on
    if off.any():
        edges = np.flatnonzero(np.diff(np.concatenate([[0], off.astype(int), [0]])))
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            ax.axvspan(t[a], t[b - 1], color="0.9", lw=0)


def _rms_pair(res: Any, forms: tuple[str, str], title: str, path: Path) -> None:
    fig, axes = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    for ax, data, label in ((axes[0], res.h_err_m, "altitude error rms (m)"),
                            (axes[1], res.vd_err_mps, "velocity (down) error rms (m/s)")):
        _shade_gaps(ax, res.t_s, res.gps_on)
        for f in forms:
            c, ls = _STYLE[f]
            ax.plot(res.t_s, np.sqrt(np.mean(data[f] ** 2, axis=0)), color=c, ls=ls, lw=1, label=f)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right")
    axes[0].set_title(title)
    axes[1].set_xlabel("t (s); shaded: no GPS")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_figures(res: Any, out_dir: Path) -> list[str]:
    """Write sokolovic_fig{3,5,6,7}.png into out_dir from a `SokolovicRuns`; return the file names."""
    out_dir = Path(out_dir)
    names = []
    p = SokolovicParams()
    h, _, _ = trajectory(res.t_s, p)
    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    axes[0].plot(res.t_s, h, "k", lw=1)
    axes[0].set_ylabel("altitude (m)")
    axes[0].set_title("Fig. 3 (ours): altitude profile")
    _shade_gaps(axes[1], res.t_s, res.gps_on)
    for f in res.h_err_m:
        c, ls = _STYLE[f]
        axes[1].plot(res.t_s, res.h_err_m[f][0], color=c, ls=ls, lw=0.8, label=f"{f}, run 0")
    axes[1].set_ylabel("altitude error (m)")
    axes[1].set_xlabel("t (s); shaded: no GPS")
    axes[1].legend(loc="upper right")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out_dir / "sokolovic_fig3.png", dpi=110)
    plt.close(fig)
    names.append("sokolovic_fig3.png")
    for num, forms in ((5, ("constant", "tanh")), (6, ("constant", "sinh")), (7, ("tanh", "sinh"))):
        if all(f in res.h_err_m for f in forms):
            name = f"sokolovic_fig{num}.png"
            _rms_pair(res, forms, f"Fig. {num} (ours): rms error, {forms[0]} vs {forms[1]} gains", out_dir / name)
            names.append(name)
    return names
