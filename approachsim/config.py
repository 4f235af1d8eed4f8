"""Strict reading of TOML tables into typed values: every error names the field and what is allowed.

`Section` wraps one TOML table. Each getter consumes a key; `done()` rejects keys nobody asked for. Used by
profile.py and by each stage's own config parser (sensors, nav, faults, evaluation, studies), so every
profile error reads the same: ``runway.glidepath_deg: must be in [1, 10] deg, got 0``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

_MISSING = object()


class ProfileError(ValueError):
    """A profile, study file or CLI option is malformed. The message names the field; the CLI exits 2."""


class Section:
    """One TOML table being read. `path` is the dotted name used in error messages ("environment")."""

    def __init__(self, data: Any, path: str) -> None:
        if not isinstance(data, dict):
            raise ProfileError(f"{path}: must be a table, got {type(data).__name__}")
        self._data = dict(data)
        self.path = path
        self._used: set[str] = set()

    def _name(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        """True when the table holds `key`."""
        return key in self._data

    def raw(self, key: str, default: Any = _MISSING) -> Any:
        """The untyped value of `key`; missing and no default is an error naming the field."""
        self._used.add(key)
        if key not in self._data:
            if default is _MISSING:
                raise ProfileError(f"{self._name(key)}: missing (required)")
            return default
        return self._data[key]

    def number(
        self,
        key: str,
        default: Any = _MISSING,
        *,
        lo: float | None = None,
        hi: float | None = None,
        lo_open: bool = False,
        hi_open: bool = False,
        unit: str = "",
    ) -> float:
        """A finite real number within [lo, hi] (open ends where asked)."""
        v = self.raw(key, default)
        if v is default and default is not _MISSING:
            return v
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise ProfileError(f"{self._name(key)}: must be a number{_unit(unit)}, got {v!r}")
        v = float(v)
        if not math.isfinite(v):
            raise ProfileError(f"{self._name(key)}: must be finite, got {v!r}")
        bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
        bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
        if bad_lo or bad_hi:
            lb = "(" if lo_open else "["
            rb = ")" if hi_open else "]"
            rng = f"{lb}{_fmt(lo, '-inf')}, {_fmt(hi, 'inf')}{rb}"
            raise ProfileError(f"{self._name(key)}: must be in {rng}{_unit(unit)}, got {v:g}")
        return v

    def integer(self, key: str, default: Any = _MISSING, *, lo: int | None = None, hi: int | None = None) -> int:
        """An integer within [lo, hi]."""
        v = self.raw(key, default)
        if v is default and default is not _MISSING:
            return v
        if isinstance(v, bool) or not isinstance(v, int):
            raise ProfileError(f"{self._name(key)}: must be an integer, got {v!r}")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise ProfileError(f"{self._name(key)}: must be in [{_fmt(lo, '-inf')}, {_fmt(hi, 'inf')}], got {v}")
        return v

    def boolean(self, key: str, default: Any = _MISSING) -> bool:
        """true or false."""
        v = self.raw(key, default)
        if not isinstance(v, bool):
            raise ProfileError(f"{self._name(key)}: must be true or false, got {v!r}")
        return v

    def string(self, key: str, default: Any = _MISSING, *, choices: Sequence[str] | None = None) -> str:
        """A string, one of `choices` when given."""
        v = self.raw(key, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, str):
            raise ProfileError(f"{self._name(key)}: must be a string, got {v!r}")
        if choices is not None and v not in choices:
            raise ProfileError(f"{self._name(key)}: must be one of {', '.join(choices)}; got {v!r}")
        return v

    def numbers(self, key: str, default: Any = _MISSING, *, min_len: int = 0, unit: str = "") -> tuple[float, ...]:
        """A list of finite numbers (at least `min_len`)."""
        v = self.raw(key, default)
        if v is default and default is not _MISSING:
            return v
        if not isinstance(v, list) or any(
            isinstance(x, bool) or not isinstance(x, int | float) or not math.isfinite(x) for x in v
        ):
            raise ProfileError(f"{self._name(key)}: must be a list of numbers{_unit(unit)}, got {v!r}")
        if len(v) < min_len:
            raise ProfileError(f"{self._name(key)}: needs at least {min_len} values, got {len(v)}")
        return tuple(float(x) for x in v)

    def section(self, key: str, default_empty: bool = True) -> Section:
        """A sub-table as a Section (an empty one when absent and `default_empty`)."""
        v = self.raw(key, {} if default_empty else _MISSING)
        return Section(v, self._name(key))

    def sections(self, key: str) -> list[Section]:
        """An array of tables ([[key]]) as Sections; absent is an empty list."""
        v = self.raw(key, [])
        if not isinstance(v, list):
            raise ProfileError(f"{self._name(key)}: must be an array of tables ([[{key}]]), got {v!r}")
        return [Section(item, f"{self._name(key)}[{i}]") for i, item in enumerate(v)]

    def done(self) -> None:
        """Reject keys that no getter consumed: unknown keys are errors."""
        unknown = sorted(set(self._data) - self._used)
        if unknown:
            raise ProfileError(f"{self._name(unknown[0])}: unknown key")


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""


def _fmt(v: float | None, inf: str) -> str:
    return inf if v is None else f"{v:g}"
