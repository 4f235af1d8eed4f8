"""Constructed Gray & Maybeck per-run tables for the reproduction's tests: per-run mean squares of known RMS."""

from __future__ import annotations

import numpy as np

from approachsim.papers import gray_maybeck as gm


def mean_squares(values_ft: dict[int, list[float]], n: int, spread: float,
                 seed: int) -> dict[int, dict[str, np.ndarray]]:
    """Per-run mean squares (ft^2) of n runs whose RMS over the runs is values_ft (per case, per state of
    gm.STATES), with a seeded run-to-run spread (relative 1-sigma `spread`)."""
    rng = np.random.default_rng(seed)
    out = {}
    for c, v in values_ft.items():
        w = 1.0 + spread * rng.standard_normal(n)
        w = w / np.sqrt(np.mean(w**2))
        out[c] = {s: (v[j] * w) ** 2 for j, s in enumerate(gm.STATES)}
    return out
