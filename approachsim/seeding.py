"""Reproducible randomness: one SeedSequence per campaign, spawned per run, then per named stream.

Streams are keyed by name (a stable CRC-32 of it), not by spawn order, so adding a sensor (a new name)
never changes the noise of another. A run is reproducible alone from (campaign seed, run index).
"""

from __future__ import annotations

import zlib

import numpy as np


def stream_key(name: str) -> int:
    """Stable 32-bit key of a stream name (CRC-32 of its UTF-8 bytes)."""
    return zlib.crc32(name.encode("utf-8"))


def run_seed_sequence(seed: int, run: int) -> np.random.SeedSequence:
    """The SeedSequence of Monte Carlo run `run` of the campaign seeded `seed` (its spawn child `run`)."""
    return np.random.SeedSequence(seed, spawn_key=(run,))


def stream(seed: int, run: int, name: str) -> np.random.Generator:
    """The named random stream (e.g. "imu", "gnss", "turbulence") of one run: a PCG64 Generator."""
    ss = np.random.SeedSequence(seed, spawn_key=(run, stream_key(name)))
    return np.random.Generator(np.random.PCG64(ss))


def stream_int(seed: int, run: int, name: str) -> int:
    """A 31-bit integer seed from the named stream (for engines seeded by an int, such as JSBSim)."""
    ss = np.random.SeedSequence(seed, spawn_key=(run, stream_key(name)))
    return int(ss.generate_state(1, dtype=np.uint32)[0] & 0x7FFFFFFF)


def substream(g: np.random.Generator, name: str) -> np.random.Generator:
    """A named child stream of Generator g (seeded from g's SeedSequence + the name's key), without drawing from g.

    A model that needs a new random draw inside a stream it already has (the radar altimeter's per-run bias,
    the filter's terrain-database error) takes it from here, so the existing draws of g are untouched and the
    child is reproducible from (campaign seed, run, stream name, child name) alone.
    """
    ss = g.bit_generator.seed_seq
    if not isinstance(ss, np.random.SeedSequence):
        raise TypeError("substream needs a Generator seeded from a numpy SeedSequence")
    child = np.random.SeedSequence(ss.entropy, spawn_key=(*ss.spawn_key, stream_key(name)), pool_size=ss.pool_size)
    return np.random.Generator(np.random.PCG64(child))
