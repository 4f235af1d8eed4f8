"""Figures of one flown approach: vertical profile against the ideal glidepath, lateral deviation, airspeed,
attitude. Takes a FlightResult (duck-typed: .truth, .guidance_r_rwy) and the profile; writes PNGs."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from approachsim import units  # noqa: E402
from approachsim.profile import Profile  # noqa: E402

FIGURES = ("vertical.png", "lateral.png", "airspeed.png", "attitude.png")


def write_flight_figures(result, profile: Profile, out_dir: Path) -> list[Path]:
    """Write the four flight figures into out_dir; returns their paths."""
    t = result.truth
    x_nmi = t.r_rwy[:, 0] / units.NMI
    z_ft = t.r_rwy[:, 2] / units.FT
    gp_ft = np.asarray(profile.runway.glidepath_height_m(t.r_rwy[:, 0])) / units.FT
    paths = []

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 7), sharex=True)
    a1.plot(x_nmi, gp_ft, "k--", lw=1, label="ideal glidepath")
    a1.plot(x_nmi, z_ft, lw=1, label="aircraft (IMU point)")
    a1.set_ylabel("height above threshold (ft)")
    a1.legend()
    a1.grid(alpha=0.3)
    a2.plot(x_nmi, t.gs_dev_m / units.FT, lw=1, label="true deviation")
    gdev = result.guidance_r_rwy[:, 2] - np.asarray(profile.runway.glidepath_height_m(result.guidance_r_rwy[:, 0]))
    a2.plot(x_nmi, gdev / units.FT, lw=0.8, alpha=0.7, label="deviation guidance flew on")
    a2.set_ylabel("vertical deviation (ft, + above)")
    a2.set_xlabel("distance past the threshold (nmi)")
    a2.legend()
    a2.grid(alpha=0.3)
    fig.suptitle(f"{profile.name}: vertical profile")
    paths.append(_save(fig, out_dir / "vertical.png"))

    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(x_nmi, t.loc_dev_m / units.FT, lw=1, label="true")
    ax.plot(x_nmi, result.guidance_r_rwy[:, 1] / units.FT, lw=0.8, alpha=0.7, label="guidance")
    ax.set_xlabel("distance past the threshold (nmi)")
    ax.set_ylabel("lateral deviation (ft, + right)")
    ax.legend()
    ax.grid(alpha=0.3)
    ax.set_title(f"{profile.name}: lateral deviation from the extended centreline")
    paths.append(_save(fig, out_dir / "lateral.png"))

    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    a1.plot(t.t_s, t.airspeed_mps / units.KT, lw=1)
    a1.set_ylabel("calibrated airspeed (kt)")
    a1.grid(alpha=0.3)
    a2.plot(t.t_s, t.controls[:, 3], lw=1)
    a2.set_ylabel("throttle command")
    a2.set_xlabel("time (s)")
    a2.grid(alpha=0.3)
    fig.suptitle(f"{profile.name}: airspeed and autothrottle")
    paths.append(_save(fig, out_dir / "airspeed.png"))

    fig, axes = plt.subplots(3, 1, figsize=(9, 7), sharex=True)
    rel_heading = np.angle(np.exp(1j * (t.euler_rad[:, 2] - profile.runway.heading_rad)))
    series = (t.euler_rad[:, 0], t.euler_rad[:, 1], rel_heading)
    names = ("roll", "pitch", "heading - runway heading")
    for ax, y, name in zip(axes, series, names, strict=True):
        ax.plot(t.t_s, np.degrees(y), lw=1)
        ax.set_ylabel(f"{name} (deg)")
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle(f"{profile.name}: attitude")
    paths.append(_save(fig, out_dir / "attitude.png"))
    return paths


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
