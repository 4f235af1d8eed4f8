"""The flight loop compiled with JSBSim's C++ called from it (core/loop/direct.py, flight/jsbsim_abi.py)
flies the Python loop's flight bit for bit: guided by the truth (turbulence writes), over terrain (terrain
writes), to touchdown (the gear reads near the ground), and with the navigation in the loop (Python acting between
compiled stretches). The pointer checks refuse what is not a JSBSim object, unreadable memory reads as None, and
APPROACHSIM_JSBSIM_DIRECT=0 turns the path off."""

from __future__ import annotations

import dataclasses
import math
import platform
import sys
import tomllib
from pathlib import Path

import jsbsim
import numpy as np
import pytest

from approachsim.core import layouts
from approachsim.core.loop import direct as dk
from approachsim.core.loop import jsbsim_abi
from approachsim.flight.fdm import FDM
from approachsim.flight.run import Approach
from approachsim.flight.trim import start_condition
from approachsim.profile import parse_profile

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
SUPPORTED = (sys.implementation.name == "cpython" and sys.platform.startswith("linux")
             and platform.machine() == "x86_64")


def _profile(name: str, **runway) -> object:
    path = PROFILES / f"{name}.toml"
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data["runway"].update(runway)
    if name == "default" and not runway:
        data["terrain"] = {"distance_nmi": [12.0, 8.0, 0.0], "height_ft": [13.0, 1013.0, 13.0]}
    return parse_profile(data, source=path.resolve())


def _trimmed_io(prof) -> tuple[FDM, object]:
    approach = Approach(prof)
    fdm = FDM(approach.aircraft.jsbsim_model, approach.dt_s)
    approach._trim(fdm, start_condition(prof, approach.aircraft))
    return fdm, fdm.loop_io(layouts.RAW_FIELDS, layouts.GEAR_FIELDS, layouts.GEAR_AIRBORNE)


def _assert_same(a: object, b: object, path: str = "") -> int:
    """Every field of two results equal, arrays bit for bit (nan where nan), except which loop flew them (the
    FlightResult's `loop`, `loop_reason`: checked by the callers); returns the number of arrays."""
    if dataclasses.is_dataclass(a):
        return sum(_assert_same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
                   for f in dataclasses.fields(a) if f.name not in ("loop", "loop_reason"))
    if isinstance(a, np.ndarray):
        assert a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), path
        return 1
    if isinstance(a, float) and math.isnan(a):
        assert isinstance(b, float) and math.isnan(b), path
    else:
        assert a == b, path
    return 0


@pytest.fixture(scope="module")
def direct_available():
    """The direct path must be there on x86-64 Linux CPython (else these comparisons would compare the Python
    loop with itself); elsewhere the flight keeps the Python loop and the comparisons are skipped."""
    _, io = _trimmed_io(_profile("default"))
    if not SUPPORTED:
        assert io.direct is None
        pytest.skip("the direct JSBSim path needs CPython on x86-64 Linux")
    assert io.direct is not None and io.direct.shape == (layouts.N_D,)
    return True


def _fly_both(monkeypatch, fly) -> tuple[object, object]:
    monkeypatch.setenv(jsbsim_abi.ENV_SWITCH, "1")
    direct = fly()
    monkeypatch.setenv(jsbsim_abi.ENV_SWITCH, "0")
    python = fly()
    return direct, python


@pytest.mark.slow
@pytest.mark.parametrize("case", ["turbulent-terrain", "landing"])
def test_the_compiled_loop_flies_the_python_loops_bits(case, direct_available, monkeypatch):
    if case == "landing":  # hot and high, crosswind, flare and touchdown: the gear is read near the ground
        prof, land, max_time_s = _profile("hot-high-crosswind", start_distance_nmi=2.0), True, None
    else:  # light turbulence (gust writes) over a 1000 ft ridge (terrain writes): 30 s
        prof, land, max_time_s = _profile("default"), False, 30.0
    approach = Approach(prof, land=land)
    direct, python = _fly_both(monkeypatch, lambda: approach.fly(seed=4, run=1, max_time_s=max_time_s))
    assert _assert_same(direct, python) >= 15
    assert (direct.loop, direct.loop_reason) == ("direct", None)
    assert python.loop == "python" and python.loop_reason == f"{jsbsim_abi.ENV_SWITCH}=0"
    if case == "landing":
        assert direct.termination == "touchdown"
        assert np.isfinite(direct.touchdown_sink_mps)
    else:
        # the ridge's slope (1000 ft over 4 nmi, 0.041) under ~2 km of a 30 s flight: the terrain written changed
        assert np.ptp(direct.truth.h_m - direct.truth.h_agl_m) > 60.0


@pytest.mark.slow
@pytest.mark.parametrize("case", ["landing", "time-budget"])
def test_the_compiled_closed_loop_flies_the_python_loops_bits(case, direct_available, monkeypatch):
    """Navigation in the loop to touchdown, and cut by the time budget (the rows run out: the compiled loop's other
    exit): the compiled stretches hand over to Python at every aiding epoch and baro sample (NavInTheLoop.act), and
    the result is the Python loop's, navigation included."""
    from approachsim.loop.closed_loop import NavInTheLoop

    if case == "landing":
        prof, land, max_time_s, ends = _profile("hot-high-crosswind"), True, None, "touchdown"
    else:
        prof, land, max_time_s, ends = _profile("default", start_distance_nmi=3.0), False, 20.0, "timeout"
    approach = Approach(prof, land=land)

    def fly():
        src = NavInTheLoop(prof, seed=2, run=0, max_time_s=approach.time_budget_s)
        res = approach.fly(seed=2, run=0, nav_source=src, max_time_s=max_time_s)
        return res, src.result(res.truth)

    (res_d, nav_d), (res_p, nav_p) = _fly_both(monkeypatch, fly)
    assert res_d.termination.startswith(ends)
    if max_time_s is not None:
        assert len(res_d.truth.t_s) == int(math.ceil(max_time_s * 120.0)) + 1
    assert _assert_same(res_d, res_p) >= 15
    assert _assert_same(nav_d, nav_p) >= 5
    assert (res_d.loop, res_p.loop) == ("direct", "python")


def test_direct_reads_are_the_wrappers_reads(direct_available):
    """read_properties through the C++ getters gives LoopIO.read_near's and read's values, bit for bit."""
    _, io = _trimmed_io(_profile("default"))
    raw = np.full(layouts.N_READ, np.nan)
    for near, read in ((True, io.read_near), (False, io.read)):
        dk.read_properties(io.direct, raw, near)
        assert np.array_equal(raw, np.array(read()))


def test_direct_writes_are_the_wrappers_writes(direct_available):
    """write_and_run sets each command on its own node (distinct values read back through the wrapper), the gusts
    only when turbulent and the terrain only over a terrain profile, and steps JSBSim: two trimmed instances, one
    written through the wrappers, one compiled, read the same bits after the step."""
    names = ["fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm", "fcs/throttle-cmd-norm[0]",
             "fcs/throttle-cmd-norm[1]", "atmosphere/gust-north-fps", "atmosphere/gust-east-fps",
             "atmosphere/gust-down-fps", "position/terrain-elevation-asl-ft"]
    cmd = (0.031, -0.012, 0.007, 0.64, 1.5, -0.8, 0.3, 52.0)  # de, da, dr, thr, gust n, e, d (ft/s), terrain (ft)
    wanted = [*cmd[:4], cmd[3], *cmd[4:]]
    for turbulent, hilly in ((0.0, 1.0), (1.0, 2.0)):
        (fdm_p, io_p), (fdm_d, io_d) = _trimmed_io(_profile("default")), _trimmed_io(_profile("default"))
        before = [fdm_d.node(n).get_double_value() for n in names]
        for setter, value in zip((io_p.set_elevator, io_p.set_aileron, io_p.set_rudder, *io_p.set_throttle,
                                  *io_p.set_gust_fps, io_p.set_terrain_ft), wanted, strict=True):
            if (setter in io_p.set_gust_fps and not turbulent) or (setter is io_p.set_terrain_ft and hilly < 2):
                continue
            setter(value)
        io_p.run()
        par = np.zeros(layouts.P_STEP + layouts.N_F_PAR)
        par[layouts.P_STEP + layouts.F_TURBULENT], par[layouts.P_STEP + layouts.F_N_TERRAIN] = turbulent, hilly
        dk.write_and_run(io_d.direct, par, *cmd)
        after = [fdm_d.node(n).get_double_value() for n in names]
        written = [*range(5), *((5, 6, 7) if turbulent else ()), *((8,) if hilly >= 2 else ())]
        for i in range(len(names) - 1):
            assert after[i] == (wanted[i] if i in written else before[i]), names[i]
        # the terrain is read back from JSBSim's ground callback at the stepped position (it moved ~1e-8 ft here):
        # 1e-3 ft still tells the written 52 ft from the profile's 513 ft
        assert after[8] == pytest.approx(wanted[8] if 8 in written else before[8], abs=1e-3)
        assert [fdm_d.node(n).get_double_value() for n in names] == [fdm_p.node(n).get_double_value() for n in names]
        assert np.array_equal(np.array(io_d.read_near()), np.array(io_p.read_near()))
        assert fdm_d["simulation/sim-time-sec"] == fdm_p["simulation/sim-time-sec"] > 0.0


def test_what_is_not_a_jsbsim_object_gives_no_pointer():
    lib = jsbsim_abi.library(jsbsim._jsbsim.__file__)
    if lib is None:
        assert not SUPPORTED
        pytest.skip("the direct JSBSim path needs CPython on x86-64 Linux")
    fdm, _ = _trimmed_io(_profile("default"))
    node = fdm.node("velocities/vc-kts")
    assert lib.node_pointer(node) is not None
    assert lib.exec_pointer(fdm._fdm) is not None
    assert lib.node_pointer(fdm._fdm) is None  # an FGFDMExec is not a property node
    assert lib.exec_pointer(node) is None
    assert lib.node_pointer(object()) is None
    assert lib.node_pointer(np.zeros(4)) is None


def test_unreadable_memory_reads_as_none():
    assert jsbsim_abi._read_words([0, 8, 2**63 + 8]) == [None, None, None]
    word = jsbsim_abi._read_words([id(None)])[0]  # the reference count of None: some positive count
    assert word is None or word > 0


def test_the_switch_keeps_the_python_loop(monkeypatch):
    monkeypatch.setenv(jsbsim_abi.ENV_SWITCH, "0")
    assert jsbsim_abi.library(jsbsim._jsbsim.__file__) is None
    _, io = _trimmed_io(_profile("default"))
    assert io.direct is None
