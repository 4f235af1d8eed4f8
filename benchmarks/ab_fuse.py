"""In-process A/B of the closed loop's direct aiding-epoch inputs (branch fuse): main's per-sensor Python
(`_direct_inputs` calling h_one / channels_one, kept here as the "old" side) against the fused compiled call
(closed_loop_epoch.direct_inputs), interleaved in one warm process; CPU time (time.process_time) of `act` summed
over an approach and of the whole closed-loop approach (Approach.fly with NavInTheLoop), medians over the repeats.

    python benchmarks/ab_fuse.py [--repeat 15] [--profile profiles/default.toml]
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from approachsim.flight.run import Approach  # noqa: E402
from approachsim.loop import closed_loop as cl  # noqa: E402
from approachsim.profile import load_profile  # noqa: E402


class OldInputs(cl.NavInTheLoop):
    """NavInTheLoop with main's `_direct_inputs` (one Python call per sensor kernel, per-epoch arrays)."""

    def _direct_inputs(self, k, t, truth):  # main's code, verbatim
        ps = self.prepared
        eng = self.navigator.engine
        tol = 0.25 * self.dt
        baro_h, baro_r, radalt_h, el = cl._NAN1, 0.0, cl._NAN1, None
        rho, r_sv, sig = np.zeros((1, 0)), eng._none3, eng._none1
        recs = {}
        j = ps.sample("baro", k)
        if j is not None:
            p = ps.sensors["baro"]
            h = p.h_one(truth, j)
            recs["baro"] = cl._BaroAt(np.array([h]))
            if abs(p.errors.t_s[j] - t) <= tol:
                baro_h, baro_r = np.array([h]), float(p.baro.noise_sigma_m) ** 2
        j = ps.sample("radalt", k)
        if j is not None:
            p = ps.sensors["radalt"]
            h = p.h_one(truth, j)
            if abs(p.errors.t_s[j] - t) <= tol:
                radalt_h = np.array([h])
        j = ps.sample("gnss", k)
        if j is not None:
            p = ps.sensors["gnss"]
            if abs(p.errors.t_s[j] - t) <= tol:
                pr, valid, r_sv0, sigma, el = p.channels_one(truth, j)
                rho = np.where(valid, pr, np.nan)
                r_sv = np.ascontiguousarray(r_sv0, dtype=float)
                if not eng.channel_states:
                    scale = self.nav.nav.gps_sigma_scale
                    sig = np.ascontiguousarray(sigma if scale == 1.0 else sigma * scale, dtype=float)
                else:
                    sig = eng._code_sig
        self._recs = (k, recs)
        pl = ps.one("pseudolite", truth, k) if "pseudolite" in ps.sensors else None
        return (baro_h, baro_r, radalt_h, rho, r_sv, sig, el, *self._pseudolite_inputs(t, pl))


def timed_act(cls):
    """cls with `act` timed (CPU s summed into .act_s)."""

    class T(cls):
        act_s = 0.0

        def act(self, k, truth, code):
            c0 = time.process_time()
            super().act(k, truth, code)
            T.act_s += time.process_time() - c0

    return T


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--profile", default="profiles/default.toml")
    a = ap.parse_args()
    prof = load_profile(a.profile)
    app = Approach(prof)
    budget = app.time_budget_s
    sides = {"old": OldInputs, "new": cl.NavInTheLoop}
    timed = {k: timed_act(v) for k, v in sides.items()}
    for v in list(sides.values()) + list(timed.values()):  # warm up (compile / load every kernel)
        app.fly(seed=1, run=99, nav_source=v(prof, seed=1, run=99, max_time_s=budget))
    fly = {k: [] for k in sides}
    act = {k: [] for k in sides}
    ref = {}
    for i in range(a.repeat):
        for side in (("old", "new") if i % 2 == 0 else ("new", "old")):
            src = sides[side](prof, seed=1, run=i)  # the source made outside the timing (its errors' draw)
            src.max_time_s = budget
            c0 = time.process_time()
            res = app.fly(seed=1, run=i, nav_source=src)
            fly[side].append(time.process_time() - c0)
            out = tuple(np.array(x) for x in (res.truth.r_rwy, res.guidance_r_rwy, src._inloop.rows))
            if i in ref:  # the other side flew this run: the same bits
                same = all(np.array_equal(x, y, equal_nan=True) for x, y in zip(ref[i], out, strict=True))
                assert same, f"run {i} differs"
            ref[i] = out
            T = timed[side]
            T.act_s = 0.0
            src = T(prof, seed=1, run=i, max_time_s=budget)
            app.fly(seed=1, run=i, nav_source=src)
            act[side].append(T.act_s)
    md = statistics.median
    print(f"{a.profile}, {a.repeat} runs each, load {os.getloadavg()}")
    for name, d in (("act (CPU per approach)", act), ("closed-loop approach (CPU)", fly)):
        o, n = md(d["old"]), md(d["new"])
        print(f"  {name:28s}: old {o * 1e3:7.1f} ms, new {n * 1e3:7.1f} ms, saved {(o - n) * 1e3:6.1f} ms "
              f"({(1 - n / o) * 100:.0f} %); min old {min(d['old']) * 1e3:.1f}, new {min(d['new']) * 1e3:.1f}")


if __name__ == "__main__":
    main()
