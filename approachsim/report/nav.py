"""Figures of one navigation run: estimation error against time with the filter's +-1 and +-3 sigma
envelopes, per state group (position NED, velocity NED, attitude), and the NIS of each measurement group.
Takes a nav.system.NavRun (duck-typed: .t_epoch_s, .true_error_nav, .P_nav, .status); writes PNGs."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

FIGURES = ("nav_position.png", "nav_velocity.png", "nav_attitude.png", "nav_nis.png")

_GROUPS = (
    ("nav_position.png", "position error", slice(0, 3), ("north", "east", "down"), "m", 1.0),
    ("nav_velocity.png", "velocity error", slice(3, 6), ("north", "east", "down"), "m/s", 1.0),
    ("nav_attitude.png", "attitude error", slice(6, 9), ("roll axis (N)", "pitch axis (E)", "heading (D)"),
     "mrad", 1e3),
)


def write_nav_figures(run, out_dir: Path, title: str = "") -> list[Path]:
    """Write the error-envelope figures and the NIS figure into out_dir; returns their paths."""
    out_dir = Path(out_dir)
    t = np.asarray(run.t_epoch_s)
    err = np.asarray(run.true_error_nav)  # output - truth = -(estimation error): same envelope
    sd = np.sqrt(np.diagonal(np.asarray(run.P_nav), axis1=1, axis2=2))
    paths = []
    for fname, label, sl, axes, unit, scale in _GROUPS:
        fig, ax = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
        for i, a in enumerate(ax):
            k = sl.start + i
            s = sd[:, k] * scale
            a.fill_between(t, -3 * s, 3 * s, color="0.88", label="+-3 sigma")
            a.fill_between(t, -s, s, color="0.72", label="+-1 sigma")
            a.plot(t, err[:, k] * scale, lw=1, color="C0", label="error (output - truth)")
            a.set_ylabel(f"{axes[i]} ({unit})")
            a.grid(alpha=0.3)
        ax[0].set_title(f"{title} {label}: navigation output minus truth, filter sigma envelopes".strip())
        ax[0].legend(loc="upper right", fontsize=8)
        ax[-1].set_xlabel("time (s)")
        fig.tight_layout()
        p = out_dir / fname
        fig.savefig(p, dpi=110)
        plt.close(fig)
        paths.append(p)
    st = run.status
    fig, a = plt.subplots(figsize=(9, 4))
    groups = sorted({n.rstrip("0123456789") for n in st.name})
    for g in groups:
        m = np.char.startswith(st.name, g)
        a.semilogy(st.t_s[m], np.maximum(st.test_ratio[m], 1e-6), ".", ms=2, label=g)
    a.axhline(3.84, color="k", lw=0.8, ls="--", label="chi2(1) 95 %")
    a.set_xlabel("time (s)")
    a.set_ylabel("NIS = nu^2 / S")
    a.set_title(f"{title} normalized innovation squared per measurement".strip())
    a.legend(fontsize=8, ncol=len(groups) + 1)
    a.grid(alpha=0.3)
    fig.tight_layout()
    p = out_dir / "nav_nis.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    paths.append(p)
    return paths
