"""Generate docs/profiles.md, the reference of every key of profile, study and aircraft files, from the schema.

The schema is the parsers themselves: this script records every key the strict readers (approachsim.config.
Section getters) ask for while parsing inputs that exercise every branch (every sensor enabled, one fault of
each kind, terrain, evaluation, a study file, the shipped aircraft file), with its type, default, allowed range,
choices and unit as the parser states them. What a key means and where its default comes from are in
tools/profile_keys.toml, one entry per key; a key of the schema without an entry, or an entry for a key the
parsers no longer read, is an error, so the reference cannot fall behind the code.

    python tools/gen_profiles_doc.py           # rewrite docs/profiles.md
    python tools/gen_profiles_doc.py --check   # exit 1 if docs/profiles.md is not current (CI)
"""

from __future__ import annotations

import argparse
import copy
import functools
import math
import re
import sys
import tempfile
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from approachsim import config as _config  # noqa: E402
from approachsim.config import Section  # noqa: E402

DOC = ROOT / "docs" / "profiles.md"
KEYS = ROOT / "tools" / "profile_keys.toml"


@dataclass
class Key:
    """One key as the parser reads it."""

    table: str
    key: str
    kind: str = "any"
    required: bool = True
    default: Any = None
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    unit: str = ""
    choices: tuple[str, ...] = ()
    order: int = 0
    notes: list[str] = field(default_factory=list)


_RECORD: dict[tuple[str, str], Key] = {}
_DEPTH = [0]
_MISSING = _config._MISSING


def _table(path: str) -> str:
    return re.sub(r"\[\d+\]", "[]", path)


def _record(self: Section, kind: str, key: str, default: Any, **kw: Any) -> None:
    ident = (_table(self.path), key)
    k = _RECORD.get(ident)
    if k is None:
        k = _RECORD[ident] = Key(table=ident[0], key=key, order=len(_RECORD))
    if kind != "any" or k.kind == "any":
        k.kind = kind
    if default is not _MISSING:
        k.required = False
        if default is not None and kind != "any":
            k.default = default
    for name, value in kw.items():
        if value is None or (isinstance(value, str | tuple | list) and not value):
            continue
        setattr(k, name, tuple(value) if name == "choices" else value)


def _wrap(kind: str) -> None:
    orig = getattr(Section, kind)

    @functools.wraps(orig)
    def rec(self: Section, key: str, default: Any = _MISSING, *args: Any, **kw: Any) -> Any:
        top = _DEPTH[0] == 0
        _DEPTH[0] += 1
        try:
            if top:
                extra = {k: kw[k] for k in ("lo", "hi", "lo_open", "hi_open", "unit", "choices") if k in kw}
                _record(self, kind, key, default, **extra)
            return orig(self, key, default, *args, **kw)
        finally:
            _DEPTH[0] -= 1

    setattr(Section, kind, rec)


SERVICE_KEYS = ("service", "udre_index", "give_index", "delta_udre", "eps_fc_m", "eps_rrc_m", "eps_ltc_m", "eps_er_m",
                "rss_udre", "dfrei", "aad", "ura_m", "truth", "filter_model")
"""[sensors.gnss] keys of a GNSS service (sensors/config.py _parse_service): out of the code-preset pass."""


def install_recorder() -> None:
    """Record every key read through a Section getter (nested getters count once, as the outer one)."""
    for kind in ("raw", "number", "integer", "boolean", "string", "numbers"):
        _wrap(kind)
    orig_section, orig_sections = Section.section, Section.sections

    def section(self: Section, key: str, default_empty: bool = True) -> Section:
        _record(self, "table", key, _MISSING if not default_empty else {})
        _DEPTH[0] += 1
        try:
            return orig_section(self, key, default_empty)
        finally:
            _DEPTH[0] -= 1

    def sections(self: Section, key: str) -> list[Section]:
        _record(self, "array of tables", key, [])
        _DEPTH[0] += 1
        try:
            return orig_sections(self, key)
        finally:
            _DEPTH[0] -= 1

    Section.section, Section.sections = section, sections  # type: ignore[method-assign]


def exercise() -> dict[str, list[Key]]:
    """Parse inputs that reach every key; the recorded keys per kind of file (profile, study, aircraft)."""
    from approachsim.campaign.study import load_study
    from approachsim.flight.aircraft import parse_aircraft
    from approachsim.profile import parse_profile
    from approachsim.resources import AIRCRAFT_DIR, PROFILES_DIR
    from approachsim.sensors.config import FAULT_PARAMETERS

    base = tomllib.loads((PROFILES_DIR / "default.toml").read_text(encoding="utf-8"))
    full = copy.deepcopy(base)
    # the code presets' keys (GBAS and carrier phase are code-preset options): the default's service keys out
    gnss = full["sensors"]["gnss"]
    for k in [k for k in gnss if k in SERVICE_KEYS]:
        gnss.pop(k)
    gnss.update(code="P(Y)", multipath_model="do253", multipath_tau_s=100.0, clock_ephemeris="current")
    full["sensors"]["pseudolite"] = {"enabled": True, "units": [{"along_ft": 0.0, "cross_ft": -500.0}]}
    full["sensors"]["gnss"]["doppler"] = True
    full["sensors"]["gnss"]["corrections"] = "gbas"
    full["sensors"]["gnss"]["carrier_phase"] = True
    full["terrain"] = {"distance_nmi": [10.0, 0.0], "height_ft": [13.0, 13.0]}
    full["evaluation"] = {}
    full["aircraft"].update(approach_speed_kt=140.0, flaps_norm=1.0)
    full["environment"]["qnh_setting_error_hPa"] = 0.0
    full["environment"]["qnh_report"] = "exact"
    full["sensors"]["baro"]["temperature_scale_sigma"] = 0.12
    full["nav"]["filter_tuning"] = {}
    sizes = {"spike": {"k": 100.0, "every": 10}, "iam": {"magnitude": 10.0, "steps": [5]}, "cbm": {"magnitude": 1.0},
             "mni": {"factor": 4.0}, "step": {"magnitude": 1.0}, "ramp": {"rate": 0.1}, "outage": {}}
    assert set(sizes) == set(FAULT_PARAMETERS)
    full["faults"] = [
        {"sensor": "gnss", "kind": kind, "start_s": 10.0, "end_s": 20.0, "channel": 3, "target": "pseudorange",
         **sizes[kind]}
        for kind in FAULT_PARAMETERS
    ]
    _RECORD.clear()
    parse_profile(copy.deepcopy(full), source=PROFILES_DIR / "default.toml")
    profile_keys = list(_RECORD.values())
    # a GNSS service's keys (sensors/gnss/service.py) are read only with a service, which excludes the code presets'
    _RECORD.clear()
    svc = copy.deepcopy(base)
    for k in ("code", "multipath_model", "multipath_tau_s", "clock_ephemeris"):
        svc["sensors"]["gnss"].pop(k, None)
    for k in [k for k in svc["sensors"]["gnss"] if k in SERVICE_KEYS]:
        svc["sensors"]["gnss"].pop(k)
    svc["sensors"]["gnss"]["service"] = "sbas-l1"
    parse_profile(svc, source=PROFILES_DIR / "default.toml")
    seen = {(k.key, k.table) for k in profile_keys}
    profile_keys += [k for k in _RECORD.values() if (k.key, k.table) not in seen]

    _RECORD.clear()
    with tempfile.TemporaryDirectory() as d:
        study = Path(d) / "s.toml"
        study.write_text(
            f'name = "s"\nprofile = "{(PROFILES_DIR / "default.toml").as_posix()}"\nruns = 2\nseed = 1\n'
            'mode = "open"\n[axes]\n"environment.wind_speed_kt" = [0, 10]\n'
            '[[variant]]\nname = "v"\nset = { "environment.turbulence" = "none" }\n',
            encoding="utf-8",
        )
        load_study(study)
    # the base profile is parsed too while loading a study: keep the study's own keys only
    study_keys = [k for k in _RECORD.values() if k.table in ("", "variant[]")]
    study_keys = [k for k in study_keys if not (k.table == "" and (k.key, k.table) in _profile_top(profile_keys))]

    _RECORD.clear()
    parse_aircraft(tomllib.loads((AIRCRAFT_DIR / "737.toml").read_text(encoding="utf-8")), AIRCRAFT_DIR / "737.toml")
    aircraft_keys = list(_RECORD.values())
    return {"profile": profile_keys, "study": study_keys, "aircraft": aircraft_keys}


def _profile_top(keys: list[Key]) -> set[tuple[str, str]]:
    study_own = {"name", "profile", "runs", "seed", "mode", "axes", "variant"}
    return {(k.key, k.table) for k in keys if k.table == "" and k.key not in study_own}


def _fmt_num(v: float) -> str:
    if isinstance(v, float) and (math.isinf(v)):
        return "inf" if v > 0 else "-inf"
    return f"{v:g}" if isinstance(v, float) else str(v)


def _range(k: Key) -> str:
    if k.choices:
        return " | ".join(f"`{c}`" for c in k.choices)
    if k.lo is None and k.hi is None:
        return ""
    lb = "(" if k.lo_open else "["
    rb = ")" if k.hi_open else "]"
    lo = "-inf" if k.lo is None else _fmt_num(k.lo)
    hi = "inf" if k.hi is None else _fmt_num(k.hi)
    return f"{lb}{lo}, {hi}{rb}"


def _default(k: Key, override: str | None) -> str:
    if override is not None:
        return override
    if k.required:
        return "**required**"
    if k.default is None or k.kind in ("table", "array of tables"):
        return ""
    v = k.default
    if isinstance(v, bool):
        return f"`{str(v).lower()}`"
    if isinstance(v, str):
        return f'`"{v}"`'
    if isinstance(v, float | int):
        return f"`{_fmt_num(v)}`"
    return f"`{v}`"


def _esc(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ").strip()


def render(keys: dict[str, list[Key]], meta: dict[str, Any]) -> str:
    """docs/profiles.md from the recorded keys and their descriptions; raises SystemExit on a missing entry."""
    problems = []
    lines = [meta["intro"]["text"].rstrip(), ""]
    for kind in ("profile", "study", "aircraft"):
        entries = meta[kind]
        seen = set()
        lines += [meta["intro"][f"{kind}_heading"].rstrip(), ""]
        if f"{kind}_text" in meta["intro"]:
            lines += [meta["intro"][f"{kind}_text"].rstrip(), ""]
        tables: dict[str, list[Key]] = {"": []}
        for k in sorted(keys[kind], key=lambda k: k.order):
            if k.kind in ("table", "array of tables"):
                ident = f"{k.table}.{k.key}" if k.table else k.key
                tables.setdefault(ident + ("[]" if k.kind == "array of tables" else ""), [])
            else:
                tables.setdefault(k.table, []).append(k)
        for table, ks in tables.items():
            note = entries.get(f"{table or '_top'}._table")
            if not ks and not note:
                continue
            lines += [f"### {_title(table)}", ""]
            if note:
                seen.add(f"{table or '_top'}._table")
                lines += [note["doc"].rstrip(), ""]
            if not ks:
                continue
            lines += ["| key | type | unit | default | allowed | meaning | source of the default |",
                      "|---|---|---|---|---|---|---|"]
            for k in ks:
                ident = f"{table}.{k.key}" if table else k.key
                e = entries.get(ident)
                if e is None:
                    problems.append(f"{kind}: {ident}: no entry in tools/profile_keys.toml")
                    continue
                seen.add(ident)
                allowed = e.get("allowed", _range(k))
                lines.append(
                    f"| `{k.key}` | {e.get('type', k.kind)} | {e.get('unit', k.unit)} | "
                    f"{_esc(_default(k, e.get('default')))} | {_esc(allowed)} | {_esc(e['doc'])} | "
                    f"{_esc(e.get('source', ''))} |"
                )
            lines.append("")
        stale = sorted(set(entries) - seen)
        problems += [f"{kind}: {s}: entry in tools/profile_keys.toml for a key the parsers do not read" for s in stale]
        if f"{kind}_after" in meta["intro"]:
            lines += [meta["intro"][f"{kind}_after"].rstrip(), ""]
    if problems:
        raise SystemExit("gen_profiles_doc: " + "; ".join(problems))
    return "\n".join(lines).rstrip() + "\n"


def _title(table: str) -> str:
    if table == "":
        return "Top level"
    if table.endswith("[]"):
        return f"[[{table[:-2]}]]"
    return f"[{table}]"


def fault_kinds_table() -> str:
    """The per-kind parameter table of [[faults]], from sensors/config.py."""
    from approachsim.sensors.config import _REQUIRED, FAULT_PARAMETERS, FAULT_TARGETS, FAULT_UNITS

    rows = ["| kind | uses | required | targets (first = default) and unit of `magnitude` |", "|---|---|---|---|"]
    targets = "; ".join(
        f"{s}: " + ", ".join(f"`{t}` ({FAULT_UNITS[(s, t)]})" for t in ts) for s, ts in FAULT_TARGETS.items()
    )
    for i, (kind, params) in enumerate(FAULT_PARAMETERS.items()):
        req = f"`{_REQUIRED[kind][0]}` (not {_REQUIRED[kind][1]:g})" if kind in _REQUIRED else ""
        rows.append(f"| `{kind}` | {', '.join(f'`{p}`' for p in params) or 'the window only'} | {req} | "
                    f"{targets if i == 0 else 'as above'} |")
    return "\n".join(rows)


def generate() -> str:
    """The text of docs/profiles.md."""
    install_recorder()
    keys = exercise()
    meta = tomllib.loads(KEYS.read_text(encoding="utf-8"))
    from approachsim.nav.registry import FILTERS

    meta["profile"]["nav.filter"]["allowed"] = " | ".join(f"`{name}`" for name in FILTERS)  # checked by the registry
    meta["intro"]["profile_after"] = meta["intro"]["profile_after"].replace("{fault_kinds}", fault_kinds_table())
    return render(keys, meta)


def main(argv: list[str] | None = None) -> int:
    """Write (or with --check, compare) docs/profiles.md."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if docs/profiles.md differs from the schema")
    args = ap.parse_args(argv)
    text = generate()
    if args.check:
        current = DOC.read_text(encoding="utf-8") if DOC.is_file() else ""
        if current != text:
            sys.stderr.write("docs/profiles.md is not current: run python tools/gen_profiles_doc.py and commit it\n")
            return 1
        print("docs/profiles.md is current")
        return 0
    DOC.write_text(text, encoding="utf-8")
    print(f"wrote {DOC.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
