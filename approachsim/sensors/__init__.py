"""Sensor models: IMU, baro, radar altimeter, GPS, pseudolite, and fault injection, all from the Truth record.

The interface (every sensor; the navigation stage builds against it)
--------------------------------------------------------------------
``measure(truth, rng, *, noise=True) -> record``
    One record (approachsim.records: ImuSamples, BaroSamples, RadaltSamples, GnssSamples, PseudoliteSamples)
    with sample times t_s, the values, per-sample `valid` flags and ground-truth `fault` labels
    (faults.FAULT_CODES). ``noise=False`` zeroes every error process: the exact value (the truth's increments,
    ISA-indicated altitude, true height above terrain, geometric range). `rng` is one numpy Generator (one
    run) or a sequence of Generators (one per run): then every random field has the run axis first.

``draw(t_s, rng) -> base.SensorErrors`` and ``apply(truth, errors) -> record``
    measure = apply(truth, draw(truth.t_s, rng)). draw makes the error processes, which depend on time only
    (turn-on constants, Gauss-Markov biases, white noise, clock), never on the trajectory, with the prefix
    property: drawing for a longer time base gives bit-identical first samples. apply reads, for each
    sample in `errors`, the truth row errors.rows (and, for the IMU, the row before it) and may be called
    with any subset `errors.take(sl)`: stepwise application equals batch measure bit for bit. A closed loop
    draws once for the longest possible flight and applies one sample at a time as truth rows appear.
    GNSS and pseudolite apply take the receiver clock: ``apply(truth, errors, clock=clock_errors)``.

``base.prepare(sensor, errors, clock) -> prepared`` and ``prepared.at(truth, j) -> record``
    The closed loop's path: the errors laid out once per run (the GNSS satellite orbits of every sample, the
    pseudolites' published positions, fault masks), then one sample at a time, giving exactly (bit for bit)
    ``apply(truth, errors.sample(j))``'s record. SensorSuite.prepare does it for a suite (suite.py).

Sample grids: a sensor at rate f takes truth rows 0, d, 2d, ... with d = round(truth rate / f); the IMU
takes every row from 1 on: IMU sample j is increment k = j + 1 over (t_{k-1}, t_k], the truth's body rate
and specific force of row k-1 held over the step, the Truth's sampling convention (imu.py:
dtheta = dt w_ib_body[k-1], dv = dt f_body[k-1], body axes); apply for increment k reads rows k-1 and k.

Random streams: each sensor draws from its own named stream approachsim.seeding.stream(seed, run, name),
name = "imu", "baro", "radalt", "gnss", "pseudolite", plus "receiver_clock" for the GPS receiver clock the
GNSS and pseudolite channels share (suite.py). Adding or removing a sensor leaves the others bit-identical. A model
part added later draws from a child of its sensor's stream (seeding.substream: the GNSS carrier phase "carrier", the
radar-altimeter bias), so the sensor's existing draws stay as they were.

Faults: faults.Faulted wraps any sensor with the same interface; the profile's [[faults]] declare them.

Modules: imu (+ presets), baro (+ atmosphere), radalt, gnss (constellation, clock, receiver, gbas, carrier), pseudolite,
faults, suite (builds everything from a Profile), config (parses [sensors] and [[faults]]), states (a run's error
states for the filter), kernels (the compiled IMU, Gauss-Markov and GNSS loops; their numpy oracles stay in the
modules above).
"""
