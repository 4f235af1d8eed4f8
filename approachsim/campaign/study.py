"""Trade studies: a study file (TOML) that varies profile fields; every variant is evaluated and compared.

    name = "ins-grade-x-wind"
    profile = "default"                    # base profile: a shipped profile name or a path relative to this file
    runs = 20                              # per variant (default: the base profile's run.runs)
    seed = 1                               # the same campaign seed for every variant (common random numbers)
    mode = "open"                          # default: the base profile's run.mode

    [axes]                                 # full factorial over these profile fields (dotted paths)
    "environment.wind_speed_kt" = [0, 15]
    "environment.turbulence" = ["light", "moderate"]

    [[variant]]                            # and/or explicit variants
    name = "calm"
    set = { "environment.wind_speed_kt" = 0, "environment.turbulence" = "none" }

Every variant's profile is built and validated before anything runs, so a bad value fails at once with
one line naming the study field (and the profile field it set). Every key: docs/profiles.md.
"""

from __future__ import annotations

import copy
import itertools
import re
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from approachsim.campaign.evaluation import Evaluation, evaluate_profile
from approachsim.campaign.pipeline import spec_for
from approachsim.config import ProfileError, Section
from approachsim.profile import Profile, parse_profile
from approachsim.resources import shipped_profiles

MODES = ("closed", "open")


@dataclass(frozen=True)
class Variant:
    """One point of the study: its name, the fields it sets and the validated profile."""

    name: str
    settings: tuple[tuple[str, Any], ...]
    profile: Profile

    @property
    def slug(self) -> str:
        """A file-system safe directory name."""
        return re.sub(r"[^A-Za-z0-9_.=-]+", "_", self.name).strip("_") or "variant"


@dataclass(frozen=True)
class Study:
    """A validated study file."""

    name: str
    base: Path | None
    """The base profile's file (None: a profile built in code, approachsim.api)."""
    runs: int
    seed: int
    mode: str
    variants: tuple[Variant, ...]


def _set(data: dict, dotted: str, value: Any, field: str) -> None:
    keys = dotted.split(".")
    if not all(keys):
        raise ProfileError(f"{field}: {dotted!r} is not a dotted profile field (section.key)")
    node = data
    for k in keys[:-1]:
        nxt = node.setdefault(k, {})
        if not isinstance(nxt, dict):
            raise ProfileError(f"{field}: {dotted!r}: {k!r} is not a table in the profile")
        node = nxt
    node[keys[-1]] = value


def _fmt(v: Any) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _variant(base_data: dict, base_path: Path | None, name: str, settings: list[tuple[str, Any]],
             field: str) -> Variant:
    data = copy.deepcopy(base_data)
    for dotted, value in settings:
        _set(data, dotted, value, field)
    stem = base_path.stem if base_path is not None else "profile"
    data["name"] = f"{base_data.get('name', stem)}[{name}]"
    try:
        prof = parse_profile(data, source=base_path)
    except ProfileError as e:
        raise ProfileError(f"{field} ({name}): {e}") from None
    return Variant(name=name, settings=tuple(settings), profile=prof)


def load_study(path: str | Path) -> Study:
    """Read and validate a study file and every variant's profile; ProfileError names the bad field."""
    p = Path(path)
    if not p.is_file():
        raise ProfileError(f"study: no such file {str(p)!r}")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise ProfileError(f"study: {str(p)!r} is not valid TOML ({e})") from None
    if "runway" in data and "profile" not in data:
        raise ProfileError(
            f"study: {str(p)!r} is a profile, not a study file; a study names its base profile (profile = \"default\" "
            "or a path) and the fields to vary ([axes] or [[variant]]), see docs/profiles.md; "
            f"to evaluate this profile: approachsim evaluate {p}"
        )
    top = Section(data, "")
    name = top.string("name", p.stem)
    base_rel = top.string("profile")
    base = _base_profile(p, base_rel)
    try:
        base_data = tomllib.loads(base.read_text(encoding="utf-8"))
        base_profile = parse_profile(copy.deepcopy(base_data), source=base)
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        raise ProfileError(f"profile: base profile {base_rel!r} is not valid TOML ({e})") from None
    runs = top.integer("runs", base_profile.run.runs, lo=1, hi=100000)
    seed = top.integer("seed", base_profile.run.seed, lo=0, hi=2**63 - 1)
    mode = top.string("mode", base_profile.run.mode, choices=MODES)
    axes = top.raw("axes", {})
    if not isinstance(axes, dict):
        raise ProfileError(f"axes: must be a table of profile fields -> lists of values, got {axes!r}")
    explicit = []
    for i, vs in enumerate(top.sections("variant")):
        vname = vs.string("name", f"variant{i}")
        sets = vs.raw("set")
        if not isinstance(sets, dict) or not sets:
            raise ProfileError(f"{vs.path}.set: must be a non-empty table of profile fields, got {sets!r}")
        vs.done()
        explicit.append((vname, list(_flatten(sets)), f"{vs.path}.set"))
    top.done()
    return make_study(name, base_data, base, axes=dict(_flatten(axes)), variants=explicit, runs=runs, seed=seed,
                      mode=mode)


def make_study(name: str, base_data: dict, base: Path | None, *, axes: dict[str, Any],
               variants: list[tuple[str, list[tuple[str, Any]], str]], runs: int, seed: int, mode: str) -> Study:
    """A validated Study from the base profile's TOML data: the full factorial over `axes` (dotted profile field ->
    list of values; variants named "key=value,...") and the explicit `variants` (name, [(dotted field, value)], the
    field to name in an error). Every variant's profile is validated here; ProfileError names the bad field."""
    variants_out: list[Variant] = []
    axis_names = sorted(axes)
    axis_values = []
    for key in axis_names:
        vals = axes[key]
        if not isinstance(vals, list) or not vals:
            raise ProfileError(f"axes.{key}: must be a non-empty list of values, got {vals!r}")
        axis_values.append(vals)
    if axis_names:
        for combo in itertools.product(*axis_values):
            settings = list(zip(axis_names, combo, strict=True))
            vname = ",".join(f"{k.rsplit('.', 1)[-1]}={_fmt(v)}" for k, v in settings)
            variants_out.append(_variant(base_data, base, vname, settings, f"axes.{'/'.join(axis_names)}"))
    for vname, settings, field in variants:
        variants_out.append(_variant(base_data, base, vname, settings, field))
    if not variants_out:
        raise ProfileError("study: needs [axes] or at least one [[variant]]")
    names = [v.name for v in variants_out]
    dup = next((n for n in names if names.count(n) > 1), None)
    if dup is not None:
        raise ProfileError(f"variant: two variants are named {dup!r}")
    slugs = [v.slug for v in variants_out]
    if len(set(slugs)) != len(slugs):
        raise ProfileError("variant: two variant names map to the same directory name; rename one")
    return Study(name=name, base=base, runs=runs, seed=seed, mode=mode, variants=tuple(variants_out))


def _base_profile(study_path: Path, ref: str) -> Path:
    """The base profile: a path relative to the study file, else a shipped profile name (approachsim profiles)."""
    base = (study_path.parent / ref).resolve()
    if base.is_file():
        return base
    shipped = {s.name: s.path for s in shipped_profiles()}
    if ref in shipped:
        return shipped[ref]
    raise ProfileError(
        f"profile: no such base profile {ref!r} (a path relative to the study file, or a shipped profile: "
        f"{', '.join(shipped)})"
    )


def _flatten(d: dict, prefix: str = ""):
    """{"a": {"b": 1}, "c.d": 2} -> ("a.b", 1), ("c.d", 2) (TOML dotted keys arrive as nested tables)."""
    for k, v in d.items():
        key = f"{prefix}.{k}" if prefix else k
        if isinstance(v, dict):
            yield from _flatten(v, key)
        else:
            yield key, v


def comparison_rows(study: Study, summaries: list[dict]) -> list[dict]:
    """One row per variant: categories met, best category, errors at each decision height (ft)."""
    rows = []
    for v, s in zip(study.variants, summaries, strict=True):
        row: dict[str, Any] = {"variant": v.name, "best_category": s["best_category"] or "none",
                               "failed_runs": s["failed_runs"]}
        for cat, e in s["decision_heights"].items():
            tag = cat.replace(" ", "")
            row[f"{tag}_meets"] = e["meets"]
            for k in ("lateral_1sigma_ft", "vertical_1sigma_ft", "lateral_95_ft", "vertical_95_ft"):
                row[f"{tag}_{k}"] = e[k]
        rows.append(row)
    return rows


def evaluate_variants(
    study: Study,
    out_dir: Path | None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    spec_fn: Any = None,
) -> list[Evaluation]:
    """Evaluate every variant (the same seed and runs: common random numbers) into out_dir/<variant slug>/ (None:
    in memory); the evaluations in variant order. spec_fn(profile, mode) -> PipelineSpec (default pipeline.spec_for)."""
    spec_fn = spec_fn or spec_for
    if out_dir is not None:
        Path(out_dir).mkdir(parents=True, exist_ok=True)
    out = []
    for i, v in enumerate(study.variants, start=1):
        if progress:
            sys.stderr.write(f"study {study.name}: variant {i}/{len(study.variants)} {v.name} ({study.runs} runs)\n")
            sys.stderr.flush()
        out.append(evaluate_profile(
            v.profile, runs=study.runs, seed=study.seed, mode=study.mode,
            out_dir=None if out_dir is None else Path(out_dir) / v.slug,
            workers=workers, scheduler=scheduler, resume=resume, progress=progress,
            spec=spec_fn(v.profile, study.mode),
        ))
    return out


def write_study(study: Study, out_dir: Path, rows: list[dict]) -> None:
    """DIR/study.json (the study, its variants and the comparison rows) and DIR/study.csv (the rows)."""
    import csv
    import json

    out_dir = Path(out_dir)
    doc = {
        "study": study.name, "base_profile": None if study.base is None else str(study.base), "runs": study.runs,
        "seed": study.seed, "mode": study.mode,
        "variants": [{"name": v.name, "dir": v.slug, "set": dict(v.settings)} for v in study.variants],
        "comparison": rows,
    }
    (out_dir / "study.json").write_text(json.dumps(doc, indent=2, allow_nan=False) + "\n", encoding="utf-8")
    with open(out_dir / "study.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def run_study(
    study: Study,
    out_dir: Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    spec_fn: Any = None,
) -> list[dict]:
    """Evaluate every variant into out_dir/<variant slug>/; write study.json and study.csv; return the rows.

    spec_fn(profile, mode) -> PipelineSpec (default: the real pipeline, pipeline.spec_for).
    """
    evs = evaluate_variants(study, out_dir, workers=workers, scheduler=scheduler, resume=resume, progress=progress,
                            spec_fn=spec_fn)
    rows = comparison_rows(study, [ev.summary for ev in evs])
    write_study(study, Path(out_dir), rows)
    return rows


def comparison_table(rows: list[dict]) -> str:
    """The printed comparison: per variant, categories met and 1-sigma errors (ft) at each decision height."""
    cats = ("CATI", "CATII", "CATIII")
    width = max(12, *(len(r["variant"]) for r in rows))
    head = f"{'variant':{width}} {'best':>8} " + " ".join(f"| {c:>6} lat/vert 1s ft met" for c in cats)
    lines = [head]
    for r in rows:
        cells = []
        for c in cats:
            lat, ver = r[f"{c}_lateral_1sigma_ft"], r[f"{c}_vertical_1sigma_ft"]
            lat_s = "--" if lat is None else f"{lat:.2f}"
            ver_s = "--" if ver is None else f"{ver:.2f}"
            cells.append(f"| {lat_s:>8} / {ver_s:<8} {'YES' if r[f'{c}_meets'] else 'no':>3}")
        lines.append(f"{r['variant']:{width}} {r['best_category']:>8} " + " ".join(cells))
    return "\n".join(lines)
