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
from approachsim.nav.robust import adaptive_filter, gate_filter
from approachsim.nav.ud import make_robust_ud, make_ud


def _ekf(**tuning: Any) -> NavFilter:
    if tuning:
        raise ProfileError(f"nav.filter_tuning.{sorted(tuning)[0]}: unknown key (the optimal 'ekf' takes no tuning)")
    return KalmanFilter(name="ekf")


def _robust_bound(kind: str, tuning: dict[str, Any]) -> float:
    """The `bound` keyword of a robust filter (confidence half-width, sigma), checked; ProfileError names it."""
    unknown = sorted(set(tuning) - {"bound"})
    if unknown:
        raise ProfileError(f"nav.filter_tuning.{unknown[0]}: unknown key ('{kind}' takes only 'bound')")
    bound = tuning.get("bound", 3.0)
    if isinstance(bound, bool) or not isinstance(bound, int | float) or not 0.0 < float(bound) < float("inf"):
        raise ProfileError(
            f"nav.filter_tuning.bound: must be a positive number of sigma (e.g. 3.0) for '{kind}'; got {bound!r}"
        )
    return float(bound)


def _rkf_gate(**tuning: Any) -> NavFilter:
    return gate_filter(_robust_bound("rkf-gate", tuning))


def _rkf_adaptive(**tuning: Any) -> NavFilter:
    return adaptive_filter(_robust_bound("rkf-adaptive", tuning))


FILTERS: Mapping[str, Callable[..., NavFilter]] = MappingProxyType(
    {
        "ekf": _ekf,
        "rkf-gate": _rkf_gate,  # Hajiyev & Saltoglu eqs. 20-24
        "rkf-adaptive": _rkf_adaptive,  # Manero Contreras & Hajiyev eqs. 20-30
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
