"""`approachsim profiles [list]` and `approachsim profiles init NAME DIR [--force]`: the shipped profiles.

`list` (the default) prints every profile that comes with the package, its description and its path;
`init` copies one into DIR as DIR/NAME.toml, to be edited and run from anywhere (its aircraft file is found
in the installed package; see approachsim.resources for the lookup order). The keys are documented in
docs/profiles.md.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

from approachsim.config import ProfileError

EPILOG = """examples:
  approachsim profiles
  approachsim profiles init default ~/approaches
  approachsim evaluate ~/approaches/default.toml --runs 4"""


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `profiles` sub-command (with `list` and `init`)."""
    p = sub.add_parser(
        "profiles", help="list the shipped profiles, or copy one to a directory of yours (profiles init NAME DIR)",
        description="List the approach profiles shipped with approachsim, or copy one into a directory to edit it.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.set_defaults(func=run_list)
    ps = p.add_subparsers(dest="profiles_command", parser_class=type(p))
    pl = ps.add_parser("list", help="list the shipped profiles (the default)",
                       description="List the shipped profiles: name, description, path.")
    pl.set_defaults(func=run_list)
    pi = ps.add_parser(
        "init", help="copy a shipped profile to DIR/NAME.toml",
        description="Copy the shipped profile NAME to DIR/NAME.toml (DIR is created if needed).",
        epilog="example:\n  approachsim profiles init default ~/approaches",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    pi.add_argument("name", help="a shipped profile (see `approachsim profiles`)")
    pi.add_argument("dir", type=Path, help="directory to copy it into")
    pi.add_argument("--force", action="store_true", help="replace DIR/NAME.toml if it exists")
    pi.set_defaults(func=run_init)


def gnss_label(path: Path) -> str:
    """The GNSS receiver a profile file flies, in words (a military one says so): its [sensors.gnss] service, or the
    code preset (P(Y) by default), read from the file without building the profile."""
    import tomllib

    from approachsim.sensors.gnss.service import SERVICE_LABELS

    g = tomllib.loads(path.read_text(encoding="utf-8")).get("sensors", {}).get("gnss", {})
    if g.get("enabled", True) is False:
        return "none"
    if "service" in g:
        return SERVICE_LABELS.get(str(g["service"]), str(g["service"]))
    if g.get("corrections") == "gbas":
        return "GBAS-corrected L1 (RTCA DO-253 / ICAO Annex 10 App. B)"
    code = str(g.get("code", "P(Y)"))
    return f"code preset {code}" + (", military (PPS)" if code == "P(Y)" else "")


def run_list(args: argparse.Namespace) -> int:
    """Print the shipped profiles."""
    from approachsim.resources import shipped_profiles

    profiles = shipped_profiles()
    width = max(len(s.name) for s in profiles)
    for s in profiles:
        print(f"{s.name:{width}}  {s.description} [GNSS: {gnss_label(s.path)}]")
    print(f"\n(in {profiles[0].path.parent}; copy one with: approachsim profiles init NAME DIR)")
    return 0


def run_init(args: argparse.Namespace) -> int:
    """Copy the shipped profile NAME into DIR."""
    from approachsim.resources import shipped_profile

    src = shipped_profile(args.name, field="NAME")
    if args.dir.exists() and not args.dir.is_dir():
        raise ProfileError(f"DIR: {str(args.dir)!r} exists and is not a directory")
    dst = args.dir / src.name
    if dst.exists() and not args.force:
        raise ProfileError(f"DIR: {str(dst)!r} already exists; add --force to replace it")
    args.dir.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(src, dst)
    print(f"wrote {dst}; run it with: approachsim evaluate {dst}")
    return 0
