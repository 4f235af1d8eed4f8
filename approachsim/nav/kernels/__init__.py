"""Compiled kernels of the navigation stage: plain functions of float arrays, compiled with numba.

Each kernel is a small pure function with the equation it implements in its docstring, compiled with
``cache=True`` (the machine code is kept in __pycache__, so a second process starts without compiling), and
has a readable numpy version elsewhere in the package that serves as its test oracle (tests/unit/nav/
test_nav_kernels.py checks they agree to 1e-12 relative). The stages import these modules; the kernels import
nothing of the stages (import-linter contract in pyproject.toml).

    geodesy       WGS-84 radii, geodetic -> ECEF, the simulated world's gravity (geo.py's equations, scalar)
    strapdown     the strapdown INS mechanization over many runs and many IMU intervals (nav/ins.py's `step`)
    inloop        the closed loop's navigation row inside the flight loop's compiled step (nav/closed_loop.py)
    output        the navigation output of every row, INS - x_hat (ins.perturb + geo.geodetic_to_ecef)
    epoch         a filter epoch of one run or of a shared-covariance class in one call, and the whole open-loop
                  pass of runs with their own skies (nav/navigator.py and nav/shared.py's numpy paths)
    errormodel    the error model's F, Qc and their discretization Phi, Qd (nav/errormodel.py's
                  dynamics_reference, discretize_reference)
    kalman        the filter epoch: sparse predict, O(n^2) scalar Joseph update, shared-covariance update, the
                  Riccati segment of the converged start (nav/base.py's predict_reference, joseph_reference;
                  nav/initial.py's converged_covariance_reference)
    measurements  the baro, radar-altimeter and pseudorange rows with their innovations (nav/measurements.py)
    carrier       the carrier-phase states' dynamics, the float ambiguities' reset at a new arc and the carrier
                  row (nav/errormodel.py, nav/engine.py's reset_arcs, nav/measurements.py carrier_phase)

One aiding epoch of one run from preallocated arrays (what a compiled per-run loop calls; the arrays of the
frozen objects from errormodel.kernel_inputs, measurements.terrain_arrays / database_arrays, and the scratch
from kalman.workspace(n)):

    errormodel.dynamics(lay, q, gse, gmp, lat, h, v_ned, f_ned, c_bn, loop, held, F, Qc)
    errormodel.discretize(F, Qc, dt, phi, qd)      # False: too large for the Taylor series, use the numpy path
    kalman.predict(x, P, phi, qd, ws)
    nu, r = measurements.pseudorange(lay, x, r_ins, c_en, r_sv, rho, sigma, sv, -1, h)   # or baro, radalt
    S = kalman.update(x, P, h, nu, r, b, ws)       # optimal; kalman.gain + kalman.joseph with a gain policy

Numba's cache (`cache=True`) is keyed to each kernel's own source file: a kernel that calls a function of another
module keeps its cached machine code when only that other module changes. After editing a kernel module, delete the
cached files (`find approachsim -name "*.nbi" -delete -o -name "*.nbc" -delete`) or touch the modules that call it;
a fresh clone (CI) always compiles afresh.
"""
