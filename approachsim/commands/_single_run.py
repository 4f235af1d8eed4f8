"""The options and checks shared by the single-run commands (fly, sense, navigate)."""

from __future__ import annotations

import argparse
from pathlib import Path

from approachsim.config import ProfileError
from approachsim.profile import Profile, load_profile


def add_single_run_arguments(p: argparse.ArgumentParser) -> None:
    """PROFILE, --out, --seed, --run, --no-figures."""
    p.add_argument("profile", type=Path, help="approach profile (TOML)")
    p.add_argument("--out", required=True, type=Path, help="output directory")
    p.add_argument("--seed", type=int, default=None, help="campaign seed (default: the profile's run.seed)")
    p.add_argument("--run", type=int, default=0, help="run index within the campaign (default 0)")
    p.add_argument("--no-figures", action="store_true", help="write the data files only")


def load_single_run(args: argparse.Namespace) -> tuple[Profile, int]:
    """The validated profile and campaign seed; a bad option raises ProfileError naming it."""
    profile = load_profile(args.profile)
    seed = profile.run.seed if args.seed is None else args.seed
    if seed < 0:
        raise ProfileError(f"--seed: must be >= 0, got {seed}")
    if args.run < 0:
        raise ProfileError(f"--run: must be >= 0, got {args.run}")
    if args.out.exists() and not args.out.is_dir():
        raise ProfileError(f"--out: {str(args.out)!r} exists and is not a directory")
    return profile, seed
