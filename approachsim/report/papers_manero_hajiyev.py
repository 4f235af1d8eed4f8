"""Figures of the Manero Contreras & Hajiyev reproduction, in the style of the paper's Figures 4-6.

One figure per scenario: top, the altitude-error estimates of the IBI, IIG and fused IBIG altimeters against
the true INS altitude error (run 0, as the paper shows one realization); bottom, the Monte Carlo mean
absolute altitude error of each over time, with the fault window shaded; a third panel gives the adaptive
RKF's p(1/k) of both channels (run 0).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from approachsim.papers.manero_hajiyev import ScenarioRuns

_STYLE = {"IBI": "C0", "IIG": "C2", "IBIG": "C3"}


def _scenario(path: Path, name: str, r: ScenarioRuns, dt_s: float) -> Path:
    t = np.arange(r.dh_ins.shape[1]) * dt_s
    fig = Figure(figsize=(7, 7))
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    ax1.plot(t, r.dh_ins[0], "k-", lw=1.5, label="true INS altitude error")
    for c, col in _STYLE.items():
        ax1.plot(t, r.est[c][0], color=col, lw=0.8, label=f"{c} estimate")
        ax2.plot(t, r.abs_error(c).mean(axis=0), color=col, label=f"{c}, mean {r.mean_error(c).mean():.2f} m")
    ax1.set_ylabel("altitude error, m")
    ax1.set_title(f"Scenario {name} (cf. Fig. {3 + int(name)})")
    ax1.legend(fontsize=7, loc="upper right")
    ax2.set_ylabel("Monte Carlo mean |error|, m")
    ax2.legend(fontsize=7, loc="upper right")
    for c in ("IBI", "IIG"):
        ax3.plot(t, r.weight[c][0], color=_STYLE[c], lw=0.8, label=f"p(1/k) {c}")
    ax3.set_ylabel("p(1/k)")
    ax3.set_xlabel("time, s")
    ax3.legend(fontsize=7, loc="lower right")
    for ax in (ax1, ax2, ax3):
        ax.axvspan(200 * dt_s, 400 * dt_s, color="0.9", zorder=0)
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    return path


def plot_all(out_dir: Path, results: dict[str, ScenarioRuns], dt_s: float) -> list[Path]:
    """Write one PNG per scenario into out_dir; return their paths."""
    out_dir = Path(out_dir)
    return [_scenario(out_dir / f"manero-hajiyev_scenario{s}.png", s, r, dt_s) for s, r in results.items()]
