"""The JSBSim wrapper: the only module in approachsim that imports jsbsim.

It creates an FGFDMExec with the model data bundled in the jsbsim wheel, sets the integrators, the
atmosphere, wind and turbulence, trims, linearizes, and reads and writes properties through cached
property nodes. Every JSBSim unit (ft, fps, lbf, slug, psf, Rankine, kt) is converted to SI here.

Integrators (`simulation/integrator/*`): JSBSim 1.3.3 defaults to rectangular Euler for the rotational
rate and attitude but Adams-Bashforth 2 for the translational rate (AB3 for position). We set the
translational rate to rectangular Euler as well, so that the state sampled after step k+1 is exactly

    v_eci[k+1] = v_eci[k] + dt (C_ib[k] f_body[k] + G(r[k]))      (JSBSim FGPropagate, eRectEuler)
    q_ib[k+1]  = normalize(q_ib[k] + dt/2 q_ib[k] * w_ib_body[k])

with f_body[k], w_ib_body[k] the values read after step k (JSBSim runs FGPropagate first in a step, then
computes forces and accelerations at the new state). The sampled specific force and inertial rate of row k
are therefore the ones that carry the state from row k to row k+1: an IMU model and a strapdown integrator
see exactly what the aircraft did. Euler at 1/120 s is well inside the accuracy of the aerodynamic model.

Turbulence: JSBSim's own model is off (its MIL-F-8785C altitude dependence uses the altitude above sea
level); approachsim.flight.turbulence computes it at the height above terrain and writes it every step to
JSBSim's user gust atmosphere/gust-{north,east,down}-fps, which JSBSim adds to the wind (writes to
atmosphere/turb-*-fps do not stick in 1.3.3 when its own model is off).

The flight loop's per-step reads and writes go through one LoopIO, bound once per run. Exception to the SI rule
above: they stay in JSBSim's units, and the loop's compiled step (core/loop/flight_step.py) converts them, so that no
Python arithmetic runs per step. LoopIO.direct gives the same reads and writes to compiled code (the C++ functions
behind the nodes, flight/jsbsim_abi.py), so the whole loop can run compiled (core/loop/direct.py).
"""

from __future__ import annotations

import contextlib
import functools
import io
import math
import os
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import jsbsim
import numpy as np

from approachsim import units
from approachsim.core import layouts
from approachsim.core.loop import jsbsim_abi
from approachsim.flight.design import Linearization

INTEGRATOR_RECT_EULER = 1
"""JSBSim's FGPropagate integrator code for rectangular Euler."""

RANKINE_PER_K = 1.8


class TrimError(RuntimeError):
    """JSBSim could not trim the aircraft at the requested condition."""


@contextlib.contextmanager
def _quiet_stdout():
    """Send the process's C-level stdout (file descriptor 1) to /dev/null for the duration, and Python's sys.stdout
    too: the JSBSim module writes its C++ output through sys.stdout when that is not the process's own (a doctest,
    a notebook)."""
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError, AttributeError):
        with contextlib.redirect_stdout(io.StringIO()):
            yield
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        with contextlib.redirect_stdout(io.StringIO()):
            yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


@dataclass(frozen=True)
class InitialCondition:
    """Where and how the run starts (SI). Wind is given as the direction it blows FROM (true, rad)."""

    lat_rad: float
    lon_rad: float
    h_m: float
    """Ellipsoid height (JSBSim's sea level is the ellipsoid), m."""
    heading_rad: float
    cas_mps: float
    gamma_rad: float
    flaps_norm: float
    gear_down: bool
    terrain_m: float
    """Terrain elevation under the start point, m."""
    wind_speed_mps: float = 0.0
    wind_from_rad: float = 0.0
    isa_dev_k: float = 0.0
    sl_pressure_pa: float = 101325.0
    """The day's sea-level pressure (true QNH), Pa."""
    tanks: tuple[tuple[float, float], ...] = ()
    """Tank loading (contents lb, station x in) per JSBSim tank, set before the trim (empty: the model's)."""


class FDM:
    """One JSBSim instance flying one aircraft model at a fixed time step dt_s.

    Build once per run (creating it costs a few ms; a fresh instance guarantees that no filter,
    turbulence or engine state leaks from one run into the next).
    """

    def __init__(self, model: str, dt_s: float) -> None:
        with _quiet_stdout():  # JSBSim prints its banner from C++ on the first FGFDMExec of a process
            fdm = jsbsim.FGFDMExec(None)
            fdm.set_debug_level(0)
            loaded = fdm.load_model(model)
        if not loaded:
            raise ValueError(f"JSBSim could not load the aircraft model {model!r}")
        fdm.disable_input()  # 737.xml opens TCP/UDP input sockets at run_ic() otherwise
        fdm.disable_output()
        fdm.set_dt(dt_s)
        self._fdm = fdm
        self._pm = fdm.get_property_manager()
        self.dt_s = float(dt_s)
        self._set_integrators()

    def _set_integrators(self) -> None:
        for name in ("rate/rotational", "rate/translational", "position/rotational"):
            self._fdm[f"simulation/integrator/{name}"] = INTEGRATOR_RECT_EULER

    def node(self, name: str):
        """The cached property node of `name` (get_double_value / set_double_value); KeyError when unknown."""
        n = self._pm.get_node(name, False)
        if n is None:
            raise KeyError(f"JSBSim property {name!r} does not exist")
        return n

    def __getitem__(self, name: str) -> float:
        return float(self._fdm[name])

    def __setitem__(self, name: str, value: float) -> None:
        self._fdm[name] = value

    @property
    def run(self):
        """The bound FGFDMExec.run (one time step); returns False when JSBSim stops."""
        return self._fdm.run

    def set_atmosphere(self, isa_dev_k: float, sl_pressure_pa: float) -> None:
        """ISA temperature deviation (K) and the day's sea-level pressure (Pa)."""
        self._fdm["atmosphere/delta-T"] = isa_dev_k * RANKINE_PER_K
        self._fdm["atmosphere/P-sl-psf"] = sl_pressure_pa / units.PSF

    def set_seed(self, seed: int) -> None:
        """Seed this instance's random generator (simulation/randomseed), for any JSBSim-side randomness."""
        self._fdm["simulation/randomseed"] = int(seed)

    def direct_addresses(self, written: Sequence[str], read: Sequence[str]) -> np.ndarray | None:
        """The uint64 vector core/loop/direct.py flies on: the C++ entry points, this FGFDMExec, the nodes
        `written` then `read` (each checked, flight/jsbsim_abi.py); None when any of them is unavailable."""
        if len(written) != layouts.N_WRITE:
            raise ValueError(f"direct_addresses: {layouts.N_WRITE} written properties, got {len(written)}")
        lib = jsbsim_abi.library(jsbsim._jsbsim.__file__)
        if lib is None:
            return None
        exe = lib.exec_pointer(self._fdm)
        nodes = lib.node_pointers([self.node(name) for name in [*written, *read]])
        if exe is None or None in nodes:
            return None
        return np.array([lib.get_fn, lib.set_fn, lib.run_fn, exe, *nodes], dtype=np.uint64)

    def loop_io(self, reads: Sequence[str], near_reads: Sequence[str], near_stand_in: Sequence[float]) -> LoopIO:
        """The flight loop's property traffic, bound once per run (LoopIO)."""
        return LoopIO(self, reads, near_reads, near_stand_in)

    def initialize_and_trim(self, ic: InitialCondition) -> None:
        """Set the initial conditions, start the engines, trim (full, mode 1) and take the settling step.

        Wind goes through ic/vw-* (run_ic and do_trim clear atmosphere/wind-*); JSBSim's wind direction is
        where the wind blows TO. The speed and flight-path angle are set again after the wind.
        """
        f = self._fdm
        self.set_atmosphere(ic.isa_dev_k, ic.sl_pressure_pa)
        f["ic/lat-geod-rad"] = ic.lat_rad
        f["ic/long-gc-rad"] = ic.lon_rad
        f["ic/terrain-elevation-ft"] = ic.terrain_m / units.FT
        f["ic/h-sl-ft"] = ic.h_m / units.FT
        f["ic/psi-true-rad"] = ic.heading_rad
        f["ic/vc-kts"] = ic.cas_mps / units.KT
        f["ic/gamma-rad"] = ic.gamma_rad
        if ic.wind_speed_mps > 0.0:
            f["ic/vw-mag-fps"] = ic.wind_speed_mps / units.FPS
            f["ic/vw-dir-deg"] = math.degrees(ic.wind_from_rad + math.pi) % 360.0
            f["ic/vc-kts"] = ic.cas_mps / units.KT
            f["ic/gamma-rad"] = ic.gamma_rad
        for i, (contents_lb, x_in) in enumerate(ic.tanks):  # the weight and CG (aircraft.Mass.tank_loading)
            f[f"propulsion/tank[{i}]/contents-lbs"] = contents_lb
            f[f"propulsion/tank[{i}]/x-position"] = x_in
        f["gear/gear-cmd-norm"] = 1.0 if ic.gear_down else 0.0
        f["fcs/flap-cmd-norm"] = ic.flaps_norm
        if not f.run_ic():
            raise RuntimeError("JSBSim run_ic failed")
        f["propulsion/set-running"] = -1
        try:
            with _quiet_stdout():  # a failing trim explains itself on stdout; the exception says it in one line
                f.do_trim(1)
        except jsbsim.TrimFailureError as e:
            raise TrimError(
                f"JSBSim could not trim at {ic.cas_mps / units.KT:.0f} KCAS, flaps {ic.flaps_norm}, "
                f"gamma {math.degrees(ic.gamma_rad):.1f} deg: {e}"
            ) from None
        f.run()  # the first step after trim snaps the engines to the trimmed throttle; controls move after it

    def cas_and_path(self) -> tuple[float, float]:
        """JSBSim's own calibrated airspeed (m/s) and earth-frame flight-path angle (rad, + climbing) of the CG:
        velocities/vc-kts and atan2(-v_down, |v_north, v_east|) of the ground-relative NED velocity."""
        f = self._fdm
        vn, ve, vd = f["velocities/v-north-fps"], f["velocities/v-east-fps"], f["velocities/v-down-fps"]
        return float(f["velocities/vc-kts"]) * units.KT, math.atan2(-vd, math.hypot(vn, ve))

    def gear_location_struct_m(self, unit: int) -> np.ndarray:
        """Gear unit `unit`'s contact point in the model's structural frame (x aft, y right, z up), m:
        gear/unit[i]/{x,y,z}-position (in)."""
        return np.array([float(self._fdm[f"gear/unit[{unit}]/{c}-position"]) for c in "xyz"]) * units.IN

    def linearize(self, gamma_rad: float) -> Linearization:
        """JSBSim's FGLinearization at the current (trimmed, still-air) state."""
        lin = jsbsim.FGLinearization(self._fdm)
        A, B, _C, _D = lin.state_space
        return Linearization(
            A=np.array(A, dtype=float),
            B=np.array(B, dtype=float),
            vt_mps=float(self._fdm["velocities/vt-fps"]) * units.FPS,
            gamma_rad=gamma_rad,
        )


class LoopIO:
    """The flight loop's JSBSim property traffic of one run, bound once: one call reads a step's inputs, bound
    setters write the commands. Values are in JSBSim's units (the compiled step converts them: core/loop/flight_step).

        read()       -> (*reads, *near_stand_in)   the properties `reads`, the near-ground ones stood in for
        read_near()  -> (*reads, *near_reads)      the same with the near-ground properties read
        run()                                      one JSBSim step (FGFDMExec.run)
        set_elevator, set_aileron, set_rudder, set_throttle (two engines: set_throttle[0], [1])   normalized
        set_gust_fps (north, east, down): JSBSim's user gust atmosphere/gust-*-fps, ft/s; JSBSim adds it to the
            wind (its own turbulence model is switched off by gust_on())
        set_terrain_ft: the terrain elevation under the aircraft, ft

    The readers are tuple displays of the bound getters generated once per run, as namedtuple generates its
    methods: a step's 24 reads cost ~0.7 us that way against ~1.0 us for a comprehension over the getters, which
    matters at 31,000 steps a flight against JSBSim's ~5 us step.
    """

    def __init__(self, fdm: FDM, reads: Sequence[str], near_reads: Sequence[str],
                 near_stand_in: Sequence[float]) -> None:
        if len(near_reads) != len(near_stand_in):
            raise ValueError("LoopIO: near_stand_in needs one value per near-ground property")
        getters = [fdm.node(name).get_double_value for name in reads]
        near = [fdm.node(name).get_double_value for name in near_reads]
        self.read = _tuple_reader(getters, tuple(float(v) for v in near_stand_in))
        self.read_near = _tuple_reader(getters + near, ())
        self.run = fdm.run
        de, da, dr, thr0, thr1, gn, ge, gd, terr = (fdm.node(name).set_double_value for name in layouts.WRITTEN)
        self.set_elevator, self.set_aileron, self.set_rudder = de, da, dr
        self.set_throttle = (thr0, thr1)
        self.set_gust_fps = (gn, ge, gd)
        self.set_terrain_ft = terr
        self._fdm = fdm
        self.direct = fdm.direct_addresses(layouts.WRITTEN, [*reads, *near_reads])
        """The address vector of core/loop/direct.py (D_* layout) for the same reads and writes, or None when
        the C++ entry points cannot be used here (flight/jsbsim_abi.py): then only the Python loop flies."""

    def gust_on(self) -> None:
        """Switch JSBSim's own turbulence off: the run writes its turbulence through set_gust_fps
        (approachsim.flight.turbulence, module docstring)."""
        self._fdm["atmosphere/turb-type"] = 0


def _tuple_reader(getters: list[Callable[[], float]], constants: tuple[float, ...]) -> Callable[[], tuple]:
    """A function returning (getters[0](), getters[1](), ..., *constants): one tuple display."""
    return _reader_factory(len(getters), constants)(*getters)


@functools.cache
def _reader_factory(n: int, constants: tuple[float, ...]) -> Callable[..., Callable[[], tuple]]:
    """The factory of _tuple_reader's functions for n getters, generated once per process (compiling it costs
    more than a millisecond)."""
    names = [f"g{i}" for i in range(n)]
    items = [f"{name}()" for name in names] + [repr(c) for c in constants]
    src = (f"def make({', '.join(names)}):\n"
           f"    def read():\n"
           f"        return ({', '.join(items)},)\n"
           f"    return read\n")
    namespace: dict = {}
    exec(src, {"inf": math.inf, "nan": math.nan}, namespace)  # text built above from names and float literals
    return namespace["make"]
