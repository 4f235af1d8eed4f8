"""The GBAS channel states along the approach: the filter's slow channel error at the aircraft's own geometry.

Under GBAS the slow part of a corrected pseudorange's error (ground, ionospheric gradient, tropospheric residual;
sensors/gnss/gbas.py) has a 1-sigma S(el, G) that depends on the aircraft's geometry G = (x_air, dh, v_air): its
slant distance to the reference point, its height above it and its horizontal speed (sigma_iono = F(el) sigma_vig
(x_air + 2 tau v_air), sigma_tropo proportional to |1 - exp(-dh / h0)|). The truth draws each term as a unit-variance
Gauss-Markov series times its scale at the aircraft's position, so the slow error shrinks along the approach (the
ionospheric term from 0.13 m F(el) at 10 nmi to 0.06 m F(el) over the threshold at 4 mm/km). Airborne GBAS equipment
evaluates sigma_iono from its own distance to the reference point; the filter does the same. Its slow channel state
is x_c = S_c(t) u_c with u_c of unit variance, so over an aiding interval dt

    x_c(t) = r_c exp(-dt / tau) x_c(t - dt) + w,   r_c = S(el_c, G(t)) / S(el_c, G(t - dt)),
    Var w = S(el_c, G(t))^2 (1 - exp(-2 dt / tau))

(the transition of a Gauss-Markov process of time-varying scale; its variance is S(el_c, G(t))^2 at every epoch
when it was S^2 at the last). G(t) is the linearization point's (the reference trajectory of the shared covariance,
a run's own INS solution in the per-run filter), G(t - dt) the same point moved back along its velocity over dt
(straight flight; the speed held), the elevation held at el_c(t) (a satellite's elevation change stays in the Qd, as
without GBAS). P0 (nav/noise.py) and the converged start take the sigmas at the approach's own start
(NoiseModel.gbas_geometry, gbas.approach_geometry: the profile's start distance, glidepath, threshold crossing height
and approach speed), so the first interval scales from where the filter's variances are; until 2026-12-05 they were
at gbas.REFERENCE_GEOMETRY (a 10 nmi final's start) whatever the start, and a longer final began mismatched.

With carrier phase the ionospheric part has its own states (gio) and the slow state gse the rest (ground and
troposphere): each is scaled the same way by its own sigma's ratio (`carrier_interval`; a sigma of 0, no gradient,
scales by 1).

    scale = GbasScale.of(system)                       # None: no GBAS channel states
    gse, gmp, r = scale.interval(el, y, dt)            # the channel sigmas at G(t) and r, per row of y
    gse, gio, gmp, r, r_io = scale.carrier_interval(el, y, dt)   # carrier phase: gse, gio scaled apart
    phi, qd = scale.apply(phi, qd, el, y, dt, noise)   # a per-run model: D Phi, the channel Qd at G(t)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.core.nav import errormodel as ek
from approachsim.core.sensors import gnss as gk
from approachsim.sensors.gnss.gbas import GbasModel, station_geometry

Array = np.ndarray


@dataclass(frozen=True)
class GbasScale:
    """A GBAS reference point and its channel-sigma constants (gbas.GbasModel.channel_kernel_args)."""

    station_ecef: Array
    """(3,) the reference point, ECEF m."""
    station_h_m: float
    """Its ellipsoid height, m."""
    kernel_args: tuple
    """core/sensors/gnss.gbas_channel_sigmas's constants."""
    lay: Array
    """The filter's packed state layout (errormodel.StateLayout.packed)."""
    model: GbasModel
    """The GBAS model (its numpy carrier-phase split, gbas.GbasModel.carrier_channel_sigmas_m)."""
    carrier: bool
    """Carrier phase: the slow state without the ionosphere, and the ionosphere states gio."""

    @classmethod
    def of(cls, system: Any) -> GbasScale | None:
        """The scale of a navigation system whose GPS is GBAS-corrected with channel states, else None."""
        g = system.sensors.gnss
        lay = system.layout
        if g is None or not lay.has("gse"):
            return None
        bud = g.budget()
        if bud.gbas is None:
            return None
        st = np.asarray(bud.gbas.station_ecef(system.runway), dtype=float)
        h = float(geo.ecef_to_geodetic(st)[2])
        return cls(st, h, bud.gbas.channel_kernel_args(), lay.packed, bud.gbas, lay.has("gio"))

    def geometry(self, y: Array, dt_s: float | Array) -> tuple[Array, Array]:
        """G(t) and G(t - dt) (M, 3): (x_air m, dh m, v_air m/s) of packed navigation states y (M, 16) (lat, lon rad,
        h m, v_ned m/s first) and of the same states moved back along their velocity over dt_s (s; scalar or (M,))."""
        y = np.atleast_2d(np.asarray(y, dtype=float))
        lat, lon, h, v = y[:, 0], y[:, 1], y[:, 2], y[:, 3:6]
        dt = np.broadcast_to(np.asarray(dt_s, dtype=float), lat.shape)
        r_n, r_e = geo.radii(lat)
        lat0 = lat - v[:, 0] * dt / (r_n + h)
        lon0 = lon - v[:, 1] * dt / ((r_e + h) * np.cos(lat))
        h0 = h + v[:, 2] * dt
        out = []
        for la, lo, hh in ((lat, lon, h), (lat0, lon0, h0)):  # the truth's formula (gbas.station_geometry)
            g = station_geometry(geo.geodetic_to_ecef(la, lo, hh), hh, v, self.station_ecef, self.station_h_m)
            out.append(np.column_stack(g))
        return out[0], out[1]

    def sigmas(self, el: Array, geom: Array) -> tuple[Array, Array]:
        """The slow and fast channel-state 1-sigma (M, k), m, at elevations el (M, k) rad and geometries geom (M, 3)
        (core/sensors/gnss.gbas_channel_sigmas, nav/noise.py's elevation guard)."""
        el = np.ascontiguousarray(el, dtype=float)
        g = np.ascontiguousarray(geom, dtype=float)
        gse, gmp = np.empty(el.shape), np.empty(el.shape)
        gk.gbas_channel_sigmas(el, np.ascontiguousarray(g[:, 0]), np.ascontiguousarray(g[:, 1]),
                               np.ascontiguousarray(g[:, 2]), *self.kernel_args, gse, gmp)
        return gse, gmp

    def interval(self, el: Array, y: Array, dt_s: float | Array) -> tuple[Array, Array, Array]:
        """(gse, gmp, r) (M, k): the channel sigmas at G(t) and the slow states' scale over the interval
        r = S(el, G(t)) / S(el, G(t - dt)) (module docstring), for elevations el (M, k) rad and navigation states
        y (M, 16) (one row broadcast to el's rows)."""
        el = np.atleast_2d(np.asarray(el, dtype=float))
        y = np.broadcast_to(np.atleast_2d(np.asarray(y, dtype=float)), (el.shape[0], np.shape(y)[-1]))
        now, before = self.geometry(y, dt_s)
        gse, gmp = self.sigmas(el, now)
        g0, _ = self.sigmas(el, before)
        return gse, gmp, gse / g0

    def carrier_interval(self, el: Array, y: Array, dt_s: float | Array) -> tuple[Array, ...]:
        """Carrier phase: (gse, gio, gmp, r_gse, r_gio) (M, k): the slow state without the ionosphere
        sqrt(ground^2 + tropo^2), the ionosphere and the fast state's sigmas at G(t) (gbas.GbasModel
        .carrier_channel_sigmas_m with nav/noise.py's elevation guard) and the two slow groups' scales over the
        interval, as `interval`."""
        el = np.atleast_2d(np.asarray(el, dtype=float))
        y = np.broadcast_to(np.atleast_2d(np.asarray(y, dtype=float)), (el.shape[0], np.shape(y)[-1]))
        e = np.maximum(np.nan_to_num(el, nan=0.5), np.radians(2.0))
        now, before = self.geometry(y, dt_s)
        gse, gio, gmp = (np.ascontiguousarray(np.broadcast_to(a, e.shape), dtype=float) for a in
                         self.model.carrier_channel_sigmas_m(e, now[:, :1], now[:, 1:2], now[:, 2:3]))
        g0, i0, _ = self.model.carrier_channel_sigmas_m(e, before[:, :1], before[:, 1:2], before[:, 2:3])
        return gse, gio, gmp, _ratio(gse, g0), _ratio(gio, i0)

    def apply(self, phi: Array, qd: Array, el: Array, y: Array, dt_s: float, noise: Any) -> tuple[Array, Array]:
        """A per-run (or one-sky class's) model over the interval: copies of phi with the slow channel states'
        diagonal times r (core/nav/errormodel.scale_channels; with carrier phase the gse and gio groups each by
        its own) and of qd with their entries S(el, G(t))^2 (1 - exp(-2 dt / tau)), tau the group's
        (noise: errormodel.ErrorNoise), for the channels' elevations el (k,) rad and the linearization point y
        (16,)."""
        el1, y1 = np.asarray(el, dtype=float)[None], np.asarray(y, dtype=float)[None]
        if self.carrier:
            gse, gio, _, r, r_io = self.carrier_interval(el1, y1, dt_s)
            groups = [(ek.L_GSE, gse, r, noise.gse_tau_s), (ek.L_GIO, gio, r_io, noise.gio_tau_s)]
        else:
            gse, _, r = self.interval(el1, y1, dt_s)
            groups = [(ek.L_GSE, gse, r, noise.gse_tau_s)]
        phi, qd = np.array(phi, dtype=float), np.array(qd, dtype=float)
        for grp, sig, ratio, tau in groups:
            i0 = int(self.lay[grp])
            ek.scale_channels(phi, i0, np.ascontiguousarray(ratio[0]))
            k = np.arange(i0, i0 + sig.shape[1])
            qd[k, k] = sig[0] ** 2 * -np.expm1(-2.0 * dt_s / tau)
        return phi, qd


def _ratio(now: Array, before: Array) -> Array:
    """now / before, 1 where before is 0 (a term switched off: nothing to scale)."""
    return np.divide(now, before, out=np.ones(np.broadcast_shapes(now.shape, np.shape(before))),
                     where=np.asarray(before) > 0.0)
