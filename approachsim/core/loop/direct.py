"""The flight loop as one compiled loop: JSBSim's reads, writes and steps called from compiled code.

The Python loop of flight/run.py makes ~38 calls into JSBSim's Python wrapper a step (24-29 reads, 5-9 writes, the
step) and one compiled call; at 31,000 steps an approach that is ~4 us a step on top of JSBSim's own ~7 us. Here the
same loop runs in compiled code: the reads and writes call SGPropertyNode::getDoubleValue / setDoubleValue and the
step FGFDMExec::Run directly (the wheel's exported C++ functions, found and checked by flight/jsbsim_abi.py), and
the per-step arithmetic is the same kernels in the same order (flight_step.py fly_step, closed_step.py
fly_step_closed), so the flight is bit-identical to the Python loop's.

`d`, the uint64 vector of addresses every kernel here takes (flight/fdm.py LoopIO.direct builds it):
    D_GET, D_SET, D_RUN   the three functions
    D_EXEC                the FGFDMExec
    D_WRITE + 0..8        the written nodes: elevator, aileron, rudder, throttle 0, throttle 1 (normalized),
                          gust north, east, down (ft/s), terrain elevation (ft)
    D_READ + i            kernels.RAW_FIELDS then kernels.GEAR_FIELDS (N_READ nodes)
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from approachsim.core import layouts
from approachsim.core.jit import njit
from approachsim.core.layouts import (
    D_EXEC,
    D_GET,
    D_READ,
    D_RUN,
    D_SET,
    D_WRITE,
    GEAR_AIRBORNE,
    GEAR_FIELDS,
    N_RAW,
    N_READ,
    WRITE_DA,
    WRITE_DE,
    WRITE_DR,
    WRITE_GD,
    WRITE_GE,
    WRITE_GN,
    WRITE_TERRAIN,
    WRITE_THR0,
    WRITE_THR1,
)
from approachsim.core.loop import closed_step as ck
from approachsim.core.loop import flight_step as fk

Array = np.ndarray

_GEAR_AIRBORNE = np.array(GEAR_AIRBORNE)
_N_GEAR = len(GEAR_FIELDS)
_I8P = ir.IntType(8).as_pointer()


@intrinsic
def _get(typingctx, fn, node):
    """double SGPropertyNode::getDoubleValue() const, at address fn, on the node at address node."""
    sig = types.float64(types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.DoubleType(), [_I8P])
        return builder.call(builder.inttoptr(args[0], fnty.as_pointer()), [builder.inttoptr(args[1], _I8P)])

    return sig, codegen


@intrinsic
def _set(typingctx, fn, node, value):
    """bool SGPropertyNode::setDoubleValue(double), its result dropped (as the Python loop drops it)."""
    sig = types.void(types.uint64, types.uint64, types.float64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(8), [_I8P, ir.DoubleType()])
        builder.call(builder.inttoptr(args[0], fnty.as_pointer()), [builder.inttoptr(args[1], _I8P), args[2]])
        return context.get_dummy_value()

    return sig, codegen


@intrinsic
def _run(typingctx, fn, exe):
    """bool JSBSim::FGFDMExec::Run(), its result dropped (as the Python loop drops it)."""
    sig = types.void(types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        fnty = ir.FunctionType(ir.IntType(8), [_I8P])
        builder.call(builder.inttoptr(args[0], fnty.as_pointer()), [builder.inttoptr(args[1], _I8P)])
        return context.get_dummy_value()

    return sig, codegen


@njit(cache=True)
def read_properties(d: Array, raw: Array, near: bool) -> None:
    """A step's reads into raw (N_READ,): RAW_FIELDS, then GEAR_FIELDS when near, else GEAR_AIRBORNE (LoopIO's
    read_near / read)."""
    get = d[D_GET]
    n = N_READ if near else N_RAW
    for i in range(n):
        raw[i] = _get(get, d[D_READ + i])
    if not near:
        for i in range(_N_GEAR):
            raw[N_RAW + i] = _GEAR_AIRBORNE[i]


@njit(cache=True)
def write_and_run(d: Array, par: Array, de: float, da: float, dr: float, thr: float, gn: float, ge: float,
                  gd: float, terr_ft: float) -> None:
    """A step's writes in the Python loop's order (the gusts when turbulent or the mean wind varies, the terrain
    when it has more than one point), then JSBSim's step."""
    s = d[D_SET]
    w = D_WRITE
    _set(s, d[w + WRITE_DE], de)
    _set(s, d[w + WRITE_DA], da)
    _set(s, d[w + WRITE_DR], dr)
    _set(s, d[w + WRITE_THR0], thr)
    _set(s, d[w + WRITE_THR1], thr)
    if par[layouts.P_STEP + layouts.F_TURBULENT] != 0.0 or par[layouts.P_STEP + layouts.F_WIND_VARIES] != 0.0:
        _set(s, d[w + WRITE_GN], gn)
        _set(s, d[w + WRITE_GE], ge)
        _set(s, d[w + WRITE_GD], gd)
    if par[layouts.P_STEP + layouts.F_N_TERRAIN] > 1:
        _set(s, d[w + WRITE_TERRAIN], terr_ft)
    _run(d[D_RUN], d[D_EXEC])


@njit(cache=True)
def fly_guided(d: Array, raw: Array, buf: Array, nu: Array, par: Array, st: Array) -> tuple[int, int]:
    """The whole flight guided by the truth (run.py's loop with no navigation source): rows 0.. of buf until a
    termination or buf's last row. Returns (the last row k, its TERM_* code)."""
    code = fk.TERM_NONE
    near = True
    k = 0
    for k in range(buf.shape[0]):
        read_properties(d, raw, near)
        code, de, da, dr, thr, gn, ge, gd, terr_ft, near = fk.fly_step(k, raw, buf, nu, par, st, True)
        if code:
            break
        write_and_run(d, par, de, da, dr, thr, gn, ge, gd, terr_ft)
    return k, code


@njit(cache=True)
def fly_closed(k0: int, pending: bool, cmd: Array, near: bool, d: Array, raw: Array, buf: Array, nu: Array,
               par: Array, st: Array, nw: Array, fa: Array, ia: Array) -> tuple[int, int, int, bool]:
    """The closed loop's flight from row k0 until the navigation needs Python (fly_step_closed's NAV_* bits), a
    termination, or buf's end. With `pending`, first the writes of cmd (elevator, aileron, rudder, throttle, gusts
    (ft/s), terrain (ft); the commands of row k0 - 1, set after Python acted) and JSBSim's step.

    Returns (row k, TERM_* code, NAV_* bits, read the gear at the next step). With NAV_* bits, cmd[4:8] holds row
    k's gusts and terrain for the next call; k == buf.shape[0] when the rows ran out."""
    if pending:
        write_and_run(d, par, cmd[0], cmd[1], cmd[2], cmd[3], cmd[4], cmd[5], cmd[6], cmd[7])
    for k in range(k0, buf.shape[0]):
        read_properties(d, raw, near)
        code, ncode, de, da, dr, thr, gn, ge, gd, terr_ft, near = ck.fly_step_closed(k, raw, buf, nu, par, st,
                                                                                     nw, fa, ia)
        if ncode:
            cmd[4], cmd[5], cmd[6], cmd[7] = gn, ge, gd, terr_ft
            return k, code, ncode, near
        if code:
            return k, code, 0, near
        write_and_run(d, par, de, da, dr, thr, gn, ge, gd, terr_ft)
    return buf.shape[0], fk.TERM_NONE, 0, near
