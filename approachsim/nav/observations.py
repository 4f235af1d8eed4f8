"""The measurements available to the navigation filter at one aiding epoch, for N runs: a plain record.

    obs = Observations.at(records, t_s, tol_s, batched)      # from whole sensor records (run axis first)
    obs.run(i)                                             # run i alone (a run axis of length 1)
    obs.schedule()                                         # (N, k) which measurement each run has

Values have a leading run axis; a missing or invalid sample is nan. The GNSS geometry (satellite positions,
nominal 1-sigma, elevation) is one sky shared by the runs, or with `per_run_sky` (each run its own constellation
epoch) one per run on a leading run axis. Every scalar measurement the filter takes is named by a `Source`: what
it is (baro, radar altimeter, GNSS channel, pseudolite unit, loosely coupled fix) and its channel, so that nothing
downstream parses a name back into an index.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

Array = np.ndarray

BARO, RADALT, GPS, PL, FIX, CP = "baro", "radalt", "gps", "pl", "gnss", "cp"
"""Source kinds: baro altitude, radar altitude, a GNSS channel's pseudorange, a pseudolite's pseudorange, a
loosely coupled GNSS position fix, a GNSS channel's carrier phase."""


@dataclass(frozen=True)
class Source:
    """An excludable measurement source: kind (module constants) and channel (GNSS channel or pseudolite unit
    index; -1 for the baro, the radar altimeter and a loose fix)."""

    kind: str
    channel: int = -1

    @property
    def name(self) -> str:
        """The status-log name: "baro", "radalt", "gps07", "pl0", "gnss"."""
        if self.kind == GPS:
            return f"gps{self.channel:02d}"
        if self.kind == PL:
            return f"pl{self.channel}"
        if self.kind == CP:
            return f"cp{self.channel:02d}"
        return self.kind

    @property
    def unit(self) -> str:
        """What an exclusion removes (nav/fde.py): the satellite for a GNSS channel's code and carrier alike
        ("gps07" for both), else the source's own name."""
        return Source(GPS, self.channel).name if self.kind == CP else self.name

    @property
    def ranging(self) -> bool:
        """A GNSS channel or a pseudolite (a range to a transmitter; a channel's carrier is the same range)."""
        return self.kind in (GPS, PL, CP)


def _epoch_index(t_rec: Array, t: float, tol: float) -> int | None:
    """Index of the record sample at time t (within tol), or None."""
    i = int(np.searchsorted(t_rec, t - tol))
    if i < t_rec.shape[0] and abs(t_rec[i] - t) <= tol:
        return i
    return None


@dataclass(frozen=True)
class Observations:
    """One epoch's measurements of N runs (module docstring). SI; nan where a run has no valid sample."""

    t_s: float
    n_runs: int
    baro_h_m: Array | None = None
    """(N,) baro altitude, m."""
    baro_sigma_m: float = float("nan")
    """The baro's white-noise 1-sigma, m."""
    radalt_h_m: Array | None = None
    """(N,) radar altitude above the terrain, m."""
    gnss_rho_m: Array | None = None
    """(N, k) pseudorange of each GNSS channel, m (nan: not selected, not visible or invalid)."""
    gnss_r_sv_ecef: Array | None = None
    """(k, 3) satellite positions, ECEF m; (N, k, 3) with per_run_sky."""
    gnss_sigma_m: Array | None = None
    """(k,) nominal pseudorange 1-sigma at each channel's elevation, m; (N, k) with per_run_sky."""
    gnss_el_rad: Array | None = None
    """(k,) channel elevations, rad; (N, k) with per_run_sky."""
    per_run_sky: bool = False
    pl_rho_m: Array | None = None
    """(N, p) pseudolite pseudoranges, m."""
    pl_r_ecef: Array | None = None
    """(p, 3) pseudolite positions, ECEF m."""
    pl_sigma_m: Array | None = None
    """(p,) their nominal 1-sigma, m."""
    loop_held: Array | None = None
    """(N,) bool: the INS damping loop had no baro over the interval ending at this epoch (None: no loop)."""
    gnss_phi_m: Array | None = None
    """(N, k) carrier phase of each GNSS channel, m (nan where not valid; None: no carrier phase)."""
    gnss_arc: Array | None = None
    """(N, k) int: its carrier arc id (-1 where not valid; a changed id is a new ambiguity)."""

    @classmethod
    def at(cls, records: Mapping[str, Any], t: float, tol: float, batched: bool) -> Observations:
        """The measurements available at time t (within tol) from whole sensor records; batched: the records'
        values have a leading run axis (else one run)."""

        def per_run(a: Array) -> Array:
            return np.asarray(a) if batched else np.asarray(a)[None]

        kw: dict[str, Any] = {}
        n = None
        b = records.get("baro")
        if b is not None and (j := _epoch_index(b.t_s, t, tol)) is not None:
            kw["baro_h_m"] = np.where(per_run(b.valid)[:, j], per_run(b.h_baro_m)[:, j], np.nan)
            kw["baro_sigma_m"] = float(b.sigma_m[j])
            n = kw["baro_h_m"].shape[0]
        r = records.get("radalt")
        if r is not None and (j := _epoch_index(r.t_s, t, tol)) is not None:
            kw["radalt_h_m"] = np.where(per_run(r.valid)[:, j], per_run(r.h_agl_m)[:, j], np.nan)
            n = kw["radalt_h_m"].shape[0]
        g = records.get("gnss")
        if g is not None and (j := _epoch_index(g.t_s, t, tol)) is not None:
            kw["gnss_rho_m"] = np.where(per_run(g.valid)[:, j], per_run(g.pseudorange_m)[:, j], np.nan)
            if g.carrier_phase_m is not None:
                ok = per_run(g.valid)[:, j]
                kw["gnss_phi_m"] = np.where(ok, per_run(g.carrier_phase_m)[:, j], np.nan)
                kw["gnss_arc"] = np.where(ok, per_run(g.carrier_arc)[:, j], -1)
            sky = batched and bool(g.per_run_sky)
            kw.update(gnss_r_sv_ecef=g.r_sv_ecef[:, j] if sky else g.r_sv_ecef[j],
                      gnss_sigma_m=g.sigma_m[:, j] if sky else g.sigma_m[j],
                      gnss_el_rad=g.elevation_rad[:, j] if sky else g.elevation_rad[j], per_run_sky=sky)
            n = kw["gnss_rho_m"].shape[0]
        p = records.get("pseudolite")
        if p is not None and (j := _epoch_index(p.t_s, t, tol)) is not None:
            kw.update(pl_rho_m=np.where(per_run(p.valid)[:, j], per_run(p.pseudorange_m)[:, j], np.nan),
                      pl_r_ecef=p.r_pl_ecef, pl_sigma_m=p.sigma_m[j])
            n = kw["pl_rho_m"].shape[0]
        if n is None:
            imu = records.get("imu")
            n = 1 if imu is None or not batched else int(np.shape(imu.dtheta_body)[0])
        return cls(t_s=float(t), n_runs=int(n), **kw)

    @property
    def has_gnss(self) -> bool:
        return self.gnss_rho_m is not None

    def sky(self, i: int) -> tuple[Array, Array, Array]:
        """Run i's GNSS geometry: satellite positions (k, 3) ECEF m, nominal 1-sigma (k,) m, elevations (k,) rad."""
        if self.per_run_sky:
            return self.gnss_r_sv_ecef[i], self.gnss_sigma_m[i], self.gnss_el_rad[i]
        return self.gnss_r_sv_ecef, self.gnss_sigma_m, self.gnss_el_rad

    def elevations(self, i: int = 0) -> Array | None:
        """Run i's GNSS channel elevations (k,), rad (None without GNSS)."""
        if self.gnss_el_rad is None:
            return None
        return self.gnss_el_rad[i] if self.per_run_sky else self.gnss_el_rad

    def run(self, i: int) -> Observations:
        """Run i alone: its values on a run axis of length 1, its own sky as one shared sky."""
        kw: dict[str, Any] = {"n_runs": 1}
        for k in ("baro_h_m", "radalt_h_m", "gnss_rho_m", "pl_rho_m", "loop_held", "gnss_phi_m", "gnss_arc"):
            v = getattr(self, k)
            if v is not None:
                kw[k] = np.asarray(v)[i:i + 1]
        if self.per_run_sky:
            r_sv, sig, el = self.sky(i)
            kw.update(gnss_r_sv_ecef=r_sv, gnss_sigma_m=sig, gnss_el_rad=el, per_run_sky=False)
        return replace(self, **kw)

    def with_loop_held(self, held: Array) -> Observations:
        """The record with the damping loop's hold flags (N,) bool."""
        return replace(self, loop_held=np.asarray(held, dtype=bool).reshape(self.n_runs))

    def schedule(self) -> Array:
        """(N, k) bool: which measurements each run has at this epoch (baro, radalt, each GNSS channel, each
        pseudolite): runs with equal rows take the same scalar updates in the same order."""
        n = self.n_runs
        cols = [np.zeros((n, 0), dtype=bool)]
        for v in (self.baro_h_m, self.radalt_h_m, self.gnss_rho_m, self.pl_rho_m, self.gnss_phi_m):
            if v is not None:
                cols.append(np.isfinite(np.asarray(v, dtype=float)).reshape(n, -1))
        return np.concatenate(cols, axis=1)
