"""Figures of one run's sensor streams: each sensor's error against time, and the GPS sky plot.

Takes the measured records and the exact (noise=False) records of the same run (dicts by sensor name, as
SensorSuite.measure gives) and writes PNGs. Errors are measured minus exact: what the sensor adds to truth.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from approachsim import units  # noqa: E402

DEG_PER_H = 180.0 / np.pi * 3600.0


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _shade_faults(ax, t, fault) -> None:
    f = np.asarray(fault)
    if f.ndim > 1:
        f = f.max(axis=tuple(range(1, f.ndim)))
    if f.any():
        ax.fill_between(t, 0, 1, where=f > 0, transform=ax.get_xaxis_transform(), color="tab:red", alpha=0.15,
                        step="mid", label="fault injected")


def write_sensor_figures(meas: dict[str, Any], exact: dict[str, Any], out_dir: Path, title: str) -> list[Path]:
    """One error-vs-time figure per sensor present, plus gnss_sky.png; returns the paths written."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    if "imu" in meas:
        m, e = meas["imu"], exact["imu"]
        dt = m.dt_s
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
        for i, ax_name in enumerate("xyz"):
            a1.plot(m.t_s, (m.dtheta_body[:, i] - e.dtheta_body[:, i]) / dt * DEG_PER_H, lw=0.4, label=ax_name)
            a2.plot(m.t_s, (m.dv_body[:, i] - e.dv_body[:, i]) / dt / (1e-6 * units.G0), lw=0.4, label=ax_name)
        a1.set_ylabel("gyro error (deg/h)")
        a2.set_ylabel("accelerometer error (micro-g)")
        a2.set_xlabel("time (s)")
        a1.legend(loc="upper right", fontsize=8)
        _shade_faults(a1, m.t_s, m.fault)
        fig.suptitle(f"{title}: IMU errors (increment error / dt)")
        paths.append(_save(fig, out_dir / "sensor_imu.png"))
    for name, fld, label in (("baro", "h_baro_m", "baro altitude"), ("radalt", "h_agl_m", "radar altitude")):
        if name in meas:
            m, e = meas[name], exact[name]
            fig, ax = plt.subplots(figsize=(9, 4))
            err = (getattr(m, fld) - getattr(e, fld)) / units.FT
            ax.plot(m.t_s, err, lw=0.7, label=f"{label} error")
            if name == "radalt":
                ax.plot(m.t_s, m.sigma_m / units.FT, "k--", lw=0.7, label="+-1 sigma (Gray & Maybeck model)")
                ax.plot(m.t_s, -m.sigma_m / units.FT, "k--", lw=0.7)
            _shade_faults(ax, m.t_s, m.fault)
            ax.set_xlabel("time (s)")
            ax.set_ylabel("error (ft)")
            ax.legend(loc="upper right", fontsize=8)
            ax.set_title(f"{title}: {label} error (measured - exact)")
            paths.append(_save(fig, out_dir / f"sensor_{name}.png"))
    for name in ("gnss", "pseudolite"):
        if name in meas:
            m, e = meas[name], exact[name]
            fig, ax = plt.subplots(figsize=(9, 4))
            err = m.pseudorange_m - e.pseudorange_m - m.clock_bias_m[:, None]
            labels = m.prn if name == "gnss" else np.arange(err.shape[1])
            for j in range(err.shape[1]):
                if np.isfinite(err[:, j]).any():
                    ax.plot(m.t_s, err[:, j], lw=0.7, label=f"{'PRN' if name == 'gnss' else 'unit'} {labels[j]}")
            _shade_faults(ax, m.t_s, m.fault)
            ax.set_xlabel("time (s)")
            ax.set_ylabel("pseudorange error minus receiver clock (m)")
            ax.legend(loc="upper right", fontsize=7, ncol=2)
            ax.set_title(f"{title}: {name} pseudorange errors")
            paths.append(_save(fig, out_dir / f"sensor_{name}.png"))
    if "gnss" in meas:
        paths.append(sky_plot(meas["gnss"], out_dir / "gnss_sky.png", title))
    return paths


def sky_plot(rec: Any, path: Path, title: str) -> Path:
    """Polar sky plot (azimuth clockwise from north, zenith at the centre) of the visible satellites' tracks;
    selected (used) samples drawn bold."""
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    valid = np.asarray(rec.valid)
    if valid.ndim == 3:
        valid = valid[0]
    for j in range(rec.prn.shape[0]):
        vis = rec.visible[:, j]
        if not vis.any():
            continue
        az = rec.azimuth_rad[vis, j]
        zen = 90.0 - np.degrees(rec.elevation_rad[vis, j])
        ax.plot(az, zen, lw=1, color="0.6")
        used = valid[:, j]
        if used.any():
            ax.plot(rec.azimuth_rad[used, j], 90.0 - np.degrees(rec.elevation_rad[used, j]), lw=3, color="tab:blue")
        ax.text(az[-1], zen[-1], str(rec.prn[j]), fontsize=8)
    ax.set_rlim(0, 90)
    ax.set_yticks([0, 30, 60, 85])
    ax.set_yticklabels(["90", "60", "30", "5 deg"])
    ax.set_title(f"{title}: GPS sky (bold: selected)")
    return _save(fig, path)


def day_sky_plot(az_rad: np.ndarray, el_rad: np.ndarray, prn: np.ndarray, mask_rad: float, path: Path,
                 title: str) -> Path:
    """Sky plot of a day of satellite tracks (az, el: (samples, channels)) above the mask."""
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    for j in range(prn.shape[0]):
        up = el_rad[:, j] >= mask_rad
        z = np.where(up, 90.0 - np.degrees(el_rad[:, j]), np.nan)
        ax.plot(az_rad[:, j], z, ".", ms=2)
    ax.set_rlim(0, 90)
    ax.set_yticks([0, 30, 60, 90 - np.degrees(mask_rad)])
    ax.set_yticklabels(["90", "60", "30", f"{np.degrees(mask_rad):.0f} deg elev."])
    ax.set_title(title, fontsize=9)
    return _save(fig, path)
