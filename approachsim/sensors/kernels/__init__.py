"""Compiled kernels of the sensor stage: plain functions of float arrays, compiled with numba (cache=True).

Each kernel is a small pure function (scalar loops, the equation in its docstring) with a readable numpy version
in the sensor module that serves as its test oracle (tests/unit/sensors/test_sensor_kernels.py,
test_gnss_kernels.py). The sensor models import these modules; the kernels import nothing of the stages but geo's
constants (import-linter contract in pyproject.toml).

    imu    imu_apply: the IMU error application (sensors/imu.py `Imu.apply`; oracle `Imu.apply_reference`)
    noise  first_order: the Gauss-Markov recursion of every error draw (sensors/base.py `gauss_markov`; oracle
           `gauss_markov_reference`, bit-identical)
    baro   baro_apply: the baro's indicated altitude (with its lag) and errors (sensors/baro.py `Baro.apply`; oracle
           `Baro.apply_reference`, to 1e-12 of the ISA scale T0 / L)
    radalt radalt_apply: the radar altimeter's errors and validity (sensors/radalt.py `RadarAltimeter.apply`;
           oracle `RadarAltimeter.apply_reference`, bit-identical)
    pseudolite  pseudolite_apply: ranges, elevation and validity of the pseudolites (sensors/pseudolite.py
           `Pseudolite.apply`; oracle `Pseudolite.apply_reference`)
    gnss   satellite orbits, look angles, best-PDOP selection, PDOP, pseudoranges and rates (sensors/gnss/
           receiver.py `GnssReceiver.apply`; oracle `GnssReceiver.apply_reference`)
"""

from approachsim.sensors.kernels.imu import imu_apply

__all__ = ["imu_apply"]
