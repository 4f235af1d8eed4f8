"""Where the shipped profiles and aircraft files live, and how a profile finds its aircraft file.

The profiles and aircraft approach configurations are package data (``approachsim/data/profiles/*.toml``,
``approachsim/data/aircraft/*.toml``), so they come with a wheel install; in a clone, the repository's
``profiles/`` and ``aircraft/`` are links to the same directories.

Aircraft lookup for ``<name>.toml``, first match wins:

1. beside the profile: ``<profile dir>/aircraft/`` then ``<profile dir>/../aircraft/`` (the repository layout);
2. every directory of the environment variable ``APPROACHSIM_AIRCRAFT_PATH`` (``os.pathsep``-separated);
3. the installed package's ``approachsim/data/aircraft/``.

So a profile copied anywhere (``approachsim profiles init default DIR``) flies the shipped 737, and a user's
own aircraft file is picked up from beside the profile or from the environment variable.
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass
from pathlib import Path

from approachsim.config import ProfileError

DATA_DIR = Path(__file__).resolve().parent / "data"
"""The package's data directory."""
PROFILES_DIR = DATA_DIR / "profiles"
"""The shipped approach profiles."""
AIRCRAFT_DIR = DATA_DIR / "aircraft"
"""The shipped aircraft approach configurations."""
AIRCRAFT_PATH_ENV = "APPROACHSIM_AIRCRAFT_PATH"
"""Environment variable: extra aircraft directories, searched after the profile's own and before the package's."""


@dataclass(frozen=True)
class ShippedProfile:
    """A profile that comes with the package: its name (file stem), description and path."""

    name: str
    description: str
    path: Path


def shipped_profiles() -> list[ShippedProfile]:
    """The shipped profiles, sorted by name (description read from each file's ``description`` key)."""
    out = []
    for p in sorted(PROFILES_DIR.glob("*.toml")):
        try:
            desc = str(tomllib.loads(p.read_text(encoding="utf-8")).get("description", ""))
        except tomllib.TOMLDecodeError:  # a broken shipped file is a packaging bug; list it, loading will say why
            desc = "(not valid TOML)"
        out.append(ShippedProfile(name=p.stem, description=desc, path=p))
    return out


def shipped_profile(name: str, field: str = "profile") -> Path:
    """The path of the shipped profile `name`; ProfileError (naming `field` and the choices) when none exists."""
    names = [s.name for s in shipped_profiles()]
    if name not in names:
        raise ProfileError(f"{field}: no shipped profile {name!r}; one of {', '.join(names)}")
    return PROFILES_DIR / f"{name}.toml"


def aircraft_dirs(profile_source: Path | None) -> list[Path]:
    """Directories searched for aircraft files, in order (see the module docstring)."""
    dirs: list[Path] = []
    if profile_source is not None:
        here = Path(profile_source).resolve().parent
        dirs += [here / "aircraft", here.parent / "aircraft"]
    for d in os.environ.get(AIRCRAFT_PATH_ENV, "").split(os.pathsep):
        if d.strip():
            dirs.append(Path(d.strip()).expanduser())
    dirs.append(AIRCRAFT_DIR)
    unique: list[Path] = []
    for d in dirs:
        if d not in unique:
            unique.append(d)
    return unique


def find_aircraft_file(name: str, profile_source: Path | None = None) -> Path:
    """The aircraft file ``<name>.toml``; ProfileError naming ``aircraft.name`` and where it looked otherwise."""
    dirs = aircraft_dirs(profile_source)
    for d in dirs:
        p = d / f"{name}.toml"
        if p.is_file():
            return p
    shipped = ", ".join(sorted(p.stem for p in AIRCRAFT_DIR.glob("*.toml")))
    raise ProfileError(
        f"aircraft.name: no aircraft file {name}.toml in {', '.join(str(d) for d in dirs)} "
        f"(shipped: {shipped}; add a directory with ${AIRCRAFT_PATH_ENV})"
    )
