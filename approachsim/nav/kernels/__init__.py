"""Compiled kernels of the navigation stage: plain functions of float arrays, compiled with numba.

Each kernel is a small pure function with the equation it implements in its docstring, compiled with
``cache=True`` (the machine code is kept in __pycache__, so a second process starts without compiling), and
has a readable numpy version elsewhere in the package that serves as its test oracle (tests/unit/nav/
test_nav_kernels.py checks they agree to 1e-12 relative). The stages import these modules; the kernels import
nothing of the stages (import-linter contract in pyproject.toml).

    geodesy    WGS-84 radii, geodetic -> ECEF, the simulated world's gravity (geo.py's equations, scalar)
    strapdown  the strapdown INS mechanization over many runs and many IMU intervals (nav/ins.py's `step`)
    imu        the IMU error application (sensors/imu.py's `apply`)
"""
