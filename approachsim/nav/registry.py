"""Filters by name, so a profile can choose one ("ekf", "rkf-gate", "ud", ...) and fail at load if unknown.

Each entry is a factory taking the filter's tuning keywords (from the profile's nav section) and returning
an object with the NavFilter interface of nav/base.py. A variant adds one line here.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any

from approachsim.config import ProfileError
from approachsim.nav.base import KalmanFilter, NavFilter
from approachsim.nav.ud import make_robust_ud, make_ud


def _ekf(**tuning: Any) -> NavFilter:
    if tuning:
        raise ProfileError(f"nav.filter_tuning.{sorted(tuning)[0]}: unknown key (the optimal 'ekf' takes no tuning)")
    return KalmanFilter(name="ekf")


FILTERS: Mapping[str, Callable[..., NavFilter]] = MappingProxyType(
    {
        "ekf": _ekf,
        "ud": make_ud,  # Bierman update, Thornton/MWGS propagation (Chernodarov sec. 4)
        "robust-ud": make_robust_ud,  # tuning key influence = gauss | laplace | gauss-laplace | huber
        "robust-ud-gauss": lambda **t: make_robust_ud("gauss", name="robust-ud-gauss", **t),
        "robust-ud-laplace": lambda **t: make_robust_ud("laplace", name="robust-ud-laplace", **t),
        "robust-ud-gauss-laplace": lambda **t: make_robust_ud("gauss-laplace", name="robust-ud-gauss-laplace", **t),
        "robust-ud-huber": lambda **t: make_robust_ud("huber", name="robust-ud-huber", **t),
    }
)
"""Filter factories by name (read-only)."""


def make_filter(name: str, **tuning: Any) -> NavFilter:
    """The filter called `name`, built with its tuning; ProfileError names the allowed filters."""
    try:
        factory = FILTERS[name]
    except KeyError:
        raise ProfileError(f"nav.filter: must be one of {', '.join(sorted(FILTERS))}; got {name!r}") from None
    return factory(**tuning)
