"""The Python API: profiles, variants built in code, evaluations, trade studies and integrity risk, for notebooks and
scripts. The command line (approachsim/commands/) is a thin layer over these functions.

    import approachsim as asim

    base = asim.load_profile("default")                        # a shipped profile's name, or a TOML file
    nav04 = base.with_settings({"sensors.imu.grade": "nav-0.4"})   # profile keys by their TOML names, validated
    ev = asim.evaluate_profile(nav04, runs=20, seed=1)         # in memory; out="dir" writes evaluate's files
    ev.verdicts                  # {"CAT I": "meets", "CAT II": "indeterminate", "CAT III": "fails"}
    ev.summary                   # summary.json as a dict (docs/contract.md)
    ev.runs, ev.heights          # runs.parquet and heights.parquet as pandas DataFrames (the `pandas` extra)
    ev.figure("errors_vs_height")                              # a matplotlib Figure, drawn when asked

    st = asim.study(base, axes={"sensors.imu.grade": ["nav-0.4", "nav-4.0"]}, runs=20, seed=1)
    st.table                     # one row per variant (DataFrame): best category, 1-sigma per DH and axis

Every function validates its arguments as the command line does (the same one-line ProfileError naming the field)
before anything runs. Results are plain data: dicts of JSON values, DataFrames, figures; nothing holds a process or a
file open. docs/api.md has worked examples (run by the tests).
"""

from __future__ import annotations

import copy
import math
import operator
import os
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from approachsim.config import ProfileError
from approachsim.profile import Profile, parse_profile, read_profile_toml

if TYPE_CHECKING:  # pragma: no cover - type names only
    import pandas
    from matplotlib.figure import Figure

    from approachsim.campaign.result import RunResult

__all__ = [
    "EvaluationResult",
    "ProfileError",
    "ProfileSpec",
    "StudyResult",
    "evaluate_profile",
    "integrity_risk",
    "load_profile",
    "merge",
    "shipped_profiles",
    "study",
    "study_file",
]

MAX_RUNS = 100000
MAX_WORKERS = 1024
SCHEDULER_ADDRESS = re.compile(r"^(tcp|tls|inproc|ws|wss|ucx)://\S+$|^[A-Za-z0-9_.\-\[\]:]+:\d+$")
"""What a Dask scheduler address looks like (tcp://host:8786, host:8786)."""


def shipped_profiles() -> list[str]:
    """The names of the profiles that come with the package (`approachsim profiles` lists them with descriptions)."""
    from approachsim.resources import shipped_profiles as shipped

    return [s.name for s in shipped()]


@dataclass(frozen=True)
class ProfileSpec:
    """An approach profile: its TOML data, where it came from and its validated model.

    Build one with `load_profile` (a file or a shipped name) and derive variants with `with_settings`; each is
    validated exactly as a TOML file is (unknown keys, types, ranges: a ProfileError naming the field). `profile` is
    the validated model the simulation runs (approachsim.profile.Profile)."""

    data: Mapping[str, Any] = field(repr=False)
    """The profile's TOML content as parsed (tables as dicts); do not modify: use with_settings."""
    source: Path | None
    """The file it was read from, or of the profile it was derived from (its aircraft file is found beside it)."""
    profile: Profile = field(repr=False)
    """The validated model (approachsim.profile.Profile)."""
    settings: tuple[tuple[str, Any], ...] = ()
    """The (dotted key, value) pairs set in code since the file, in order."""

    @property
    def name(self) -> str:
        """The profile's name (summary.json's "profile")."""
        return self.profile.name

    @classmethod
    def from_data(cls, data: Mapping[str, Any], source: Path | None = None) -> ProfileSpec:
        """Validate a profile given as the dict that TOML parsing gives (source: where aircraft files are looked up
        beside, as for a file there)."""
        d = copy.deepcopy(dict(data))
        return cls(data=d, source=source, profile=parse_profile(copy.deepcopy(d), source=source))

    @classmethod
    def from_file(cls, path: str | Path) -> ProfileSpec:
        """Read and validate a profile file (ProfileError for a missing file, bad TOML or a bad field)."""
        return cls.from_data(read_profile_toml(path), source=Path(path).resolve())

    def with_settings(self, settings: Mapping[str, Any], *, name: str | None = None) -> ProfileSpec:
        """A variant: these profile keys set by their dotted TOML names ("sensors.imu.grade",
        "environment.wind_speed_kt", "evaluation.integrity"; every key: docs/profiles.md), validated as a TOML file
        with them would be.

        name: the variant's profile name (default "<name>[key=value,...]" with each key's last part, as a study
        names its variants). A ProfileError names the key and what is allowed."""
        if not isinstance(settings, Mapping) or not settings:
            raise ProfileError("settings: give a non-empty mapping of dotted profile keys to values")
        data = copy.deepcopy(dict(self.data))
        for dotted, value in settings.items():
            _set_dotted(data, str(dotted), value)
        if name is None:
            name = f"{self.name}[" + ",".join(f"{str(k).rsplit('.', 1)[-1]}={_fmt(v)}"
                                              for k, v in settings.items()) + "]"
        data["name"] = name
        try:
            prof = parse_profile(copy.deepcopy(data), source=self.source)
        except ProfileError as e:
            raise ProfileError(f"settings ({name}): {e}") from None
        return ProfileSpec(data=data, source=self.source, profile=prof,
                           settings=self.settings + tuple((str(k), v) for k, v in settings.items()))

    def get(self, dotted: str, default: Any = None) -> Any:
        """The value of a dotted key as written in the profile's TOML data (default when the key is absent: the
        model's default then applies, docs/profiles.md)."""
        node: Any = self.data
        for k in dotted.split("."):
            if not isinstance(node, Mapping) or k not in node:
                return default
            node = node[k]
        return node


def _fmt(v: Any) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _set_dotted(data: dict, dotted: str, value: Any) -> None:
    keys = dotted.split(".")
    if not all(keys):
        raise ProfileError(f"settings: {dotted!r} is not a dotted profile key (section.key)")
    node = data
    for k in keys[:-1]:
        nxt = node.setdefault(k, {})
        if not isinstance(nxt, dict):
            raise ProfileError(f"settings: {dotted!r}: {k!r} is not a table in the profile")
        node = nxt
    node[keys[-1]] = value


def load_profile(profile: str | Path | ProfileSpec) -> ProfileSpec:
    """A profile from a TOML file, or a shipped profile by name ("default", "gbas-cat3-candidate": shipped_profiles());
    a ProfileSpec is returned as it is. ProfileError when it is neither a file nor a shipped name, or is invalid."""
    if isinstance(profile, ProfileSpec):
        return profile
    p = Path(profile)
    if p.is_file():
        return ProfileSpec.from_file(p)
    names = shipped_profiles()
    if str(profile) in names:
        from approachsim.resources import shipped_profile

        return ProfileSpec.from_file(shipped_profile(str(profile)))
    raise ProfileError(f"profile: no such file {str(p)!r}, nor a shipped profile ({', '.join(names)})")


# ---- evaluate ----------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CampaignOptions:
    """An evaluation's checked options (check_campaign)."""

    runs: int
    seed: int
    mode: str
    land: bool
    workers: int | None
    scheduler: str | None
    out: Path | None
    resume: bool
    shard: tuple[int, int] | None


def check_campaign(profile: Profile, *, runs: int | None, seed: int | None, mode: str | None, land: bool,
                   workers: int | None, scheduler: str | None, out: str | Path | None, resume: bool, overwrite: bool,
                   shard: str | tuple[int, int] | None = None, prefix: str = "") -> CampaignOptions:
    """Validate an evaluation's options against the profile before anything runs; ProfileError names the option
    (prefix "--" for the command line's names: `--runs: must be in [1, 100000], got 0`)."""
    from approachsim.campaign.shards import parse_shard, shard_runs

    runs = _checked_int(profile.run.runs if runs is None else runs, 1, MAX_RUNS, f"{prefix}runs")
    seed = _checked_int(profile.run.seed if seed is None else seed, 0, 2**63 - 1, f"{prefix}seed")
    mode = profile.run.mode if mode is None else mode
    if mode not in ("closed", "open"):
        raise ProfileError(f"{prefix}mode: must be 'closed' or 'open', got {mode!r}")
    if land and mode != "closed":
        raise ProfileError(f"{prefix}land: landing runs are flown closed loop only (each run lands on its own "
                           f"navigation); use {prefix}mode closed (the mode is {mode})")
    if workers is not None and (_integer(workers) is None or not 1 <= workers <= MAX_WORKERS):
        raise ProfileError(f"{prefix}workers: must be in [1, {MAX_WORKERS}], got {workers}")
    if scheduler is not None:
        if workers is not None:
            raise ProfileError(f"{prefix}workers: not used with {prefix}scheduler (the Dask cluster has its own "
                               "workers)")
        if not SCHEDULER_ADDRESS.match(str(scheduler)):
            raise ProfileError(f"{prefix}scheduler: must be an address like tcp://host:8786, got {scheduler!r}")
        require_distributed(prefix)
    k_n = None
    if shard is not None:
        k_n = parse_shard(shard, f"{prefix}shard") if isinstance(shard, str) else parse_shard(
            f"{shard[0]}/{shard[1]}", f"{prefix}shard")
        shard_runs(runs, *k_n)  # fewer runs than shards: ProfileError
        if out is None:
            raise ProfileError(f"{prefix}shard: a shard's runs are merged from its directory: give {prefix}out")
    out_p = None if out is None else Path(out)
    if out_p is not None:
        if out_p.exists() and not out_p.is_dir():
            raise ProfileError(f"{prefix}out: {str(out_p)!r} exists and is not a directory")
        if resume and overwrite:
            raise ProfileError(f"{prefix}overwrite: cannot be combined with {prefix}resume")
        jl = out_p / "runs.jsonl"
        if resume and not jl.is_file():
            raise ProfileError(f"{prefix}resume: no campaign to resume in {str(out_p)!r} (no runs.jsonl); drop "
                               f"{prefix}resume to start one")
        if not resume and not overwrite and jl.is_file() and jl.stat().st_size > 0:
            raise ProfileError(
                f"{prefix}out: {str(out_p)!r} already holds a campaign; add {prefix}resume to continue it, "
                f"{prefix}overwrite to discard it, or choose another {prefix}out")
    elif resume:
        raise ProfileError(f"{prefix}resume: needs {prefix}out, the directory of the campaign to continue")
    return CampaignOptions(runs=runs, seed=seed, mode=mode, land=bool(land), workers=workers, scheduler=scheduler,
                           out=out_p, resume=bool(resume), shard=k_n)


def _integer(v: Any) -> int | None:
    """v as an int when it is an integer (numpy's too, not a bool), else None."""
    if isinstance(v, bool):
        return None
    try:
        return operator.index(v)
    except TypeError:
        return None


def _checked_int(v: Any, lo: int, hi: int, name: str) -> int:
    """v as an int in [lo, hi]; ProfileError naming it otherwise (the command line's wording)."""
    i = _integer(v)
    if i is None or not lo <= i <= hi:
        rng = f"[{lo}, 2^63)" if hi == 2**63 - 1 else f"[{lo}, {hi}]"
        raise ProfileError(f"{name}: must be in {rng}, got {v}")
    return i


def require_distributed(prefix: str = "--") -> None:
    """A Dask scheduler needs dask.distributed (the optional `dask` extra); ProfileError saying how to install it."""
    import importlib.util

    if importlib.util.find_spec("distributed") is None:
        raise ProfileError(f"{prefix}scheduler: needs dask.distributed, not installed: pip install approachsim[dask]")


def _pandas() -> Any:
    try:
        import pandas
    except ImportError:
        raise ImportError("DataFrames need pandas: pip install approachsim[pandas] (or pip install pandas)") from None
    return pandas


@dataclass(frozen=True)
class EvaluationResult:
    """A finished evaluation (or one shard of one): the contract summary and the details as plain data, the runs,
    and on demand DataFrames and figures.

    summary: summary.json's content (docs/contract.md); details: details.json's. For a shard both are None (its runs
    are scored when the shards are merged: `merge`)."""

    profile: ProfileSpec
    summary: dict | None
    details: dict | None
    results: list[RunResult] = field(repr=False)
    """Every run in run order (campaign.result.RunResult: scalars SI, `ok`, `error`)."""
    out_dir: Path | None
    """Where the files were written (None: in memory only)."""
    wall_s: float
    warnings: tuple[str, ...] = ()
    """What went wrong beside the runs (a Dask worker found failing every task), one line each."""

    def _summary(self) -> dict:
        if self.summary is None:
            raise ValueError("a shard has no summary: merge the shards (approachsim.merge) and use that result")
        return self.summary

    @property
    def verdicts(self) -> dict[str, str]:
        """The verdict per category: "meets", "fails" or "indeterminate"."""
        return {c: e["verdict"] for c, e in self._summary()["decision_heights"].items()}

    @property
    def best_category(self) -> str | None:
        """The most demanding category that meets, None when none does."""
        return self._summary()["best_category"]

    @property
    def failed_runs(self) -> int:
        """Runs that did not complete (they count against every category)."""
        return sum(not r.ok for r in self.results)

    def verdict_rows(self) -> list[dict]:
        """The verdict contract per category as plain data: 1-sigma, upper bound, limit and verdict per axis, the
        failed-runs and integrity criteria, the verdict, the runs to decide (report.html's first table)."""
        from approachsim.campaign.outputs import headline_rows

        return headline_rows(self._summary(), self.details or {})

    def table(self) -> str:
        """The verdict table `approachsim evaluate` prints."""
        from approachsim.campaign.outputs import verdict_table

        return verdict_table(self._summary(), self.details or {})

    @property
    def runs(self) -> pandas.DataFrame:
        """One row per run (runs.parquet's columns): run, ok, error and every per-run scalar, SI with the unit in the
        column name (cat1_lateral_m: the lateral error at the CAT I decision height, m)."""
        _pandas()
        from approachsim.campaign.store import runs_table

        return runs_table(self.results).to_pandas()

    @property
    def heights(self) -> pandas.DataFrame:
        """The completed runs' errors and protection levels on the height grid (heights.parquet): long form, columns
        run, index (0 = 2000 ft .. 100 = 0 ft above the threshold, 20 ft steps), lateral_m, vertical_m, ..."""
        pd = _pandas()
        from approachsim.campaign.store import heights_table

        t = heights_table(self.results)
        return pd.DataFrame({"run": [], "index": []}) if t is None else t.to_pandas()

    def figures(self, names: Sequence[str] | None = None) -> dict[str, Figure]:
        """The report's figures as matplotlib Figures (not saved), by name: errors_vs_height, histograms_dh, the
        integrity or Stanford / availability figures, sky_dop, touchdown (those the campaign has); names: a subset."""
        from approachsim.report.evaluate import evaluation_figures, series_of

        figs = evaluation_figures(self.results, self._summary(), self.details or {},
                                  series_of(self.out_dir, self.results))
        if names is None:
            return figs
        unknown = [n for n in names if n not in figs]
        if unknown:
            raise ValueError(f"figures: no figure {unknown[0]!r}; this evaluation has {', '.join(figs)}")
        return {n: figs[n] for n in names}

    def figure(self, name: str) -> Figure:
        """One figure by name (figures())."""
        return self.figures([name])[name]

    def write_report(self, out: str | Path | None = None) -> Path:
        """Write the figures and report.html into out (default: the evaluation's directory); returns its path."""
        from approachsim.report.evaluate import write_report

        d = Path(out) if out is not None else self.out_dir
        if d is None:
            raise ValueError("write_report: this evaluation ran in memory: give out=DIR")
        d.mkdir(parents=True, exist_ok=True)
        return write_report(d, self.results, self._summary(), self.details or {})


def evaluate_profile(
    profile: str | Path | ProfileSpec,
    *,
    runs: int | None = None,
    seed: int | None = None,
    mode: str | None = None,
    land: bool = False,
    out: str | Path | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    overwrite: bool = False,
    shard: str | tuple[int, int] | None = None,
    report: bool = False,
    progress: bool = True,
) -> EvaluationResult:
    """The Monte Carlo evaluation of a profile against CAT I / II / III (what `approachsim evaluate` runs).

    runs, seed, mode ("closed" | "open"): default the profile's [run] table. land: closed loop on to touchdown.
    out: write evaluate's files there (summary.json, details.json, runs.parquet, ...; None: in memory only);
    resume / overwrite an existing campaign there. workers: local processes (default every core); scheduler: a Dask
    scheduler's address instead. shard "K/N": only that slice of the runs (merge the N shard directories with
    `merge`). report: also write the figures and report.html into out. progress: the progress display on stderr.
    The same profile, seed and runs give the same numbers whatever the workers, executor or shards."""
    from approachsim.campaign.evaluation import evaluate_profile as run_evaluation
    from approachsim.campaign.pipeline import spec_for

    spec_ = load_profile(profile)
    prof = spec_.profile
    o = check_campaign(prof, runs=runs, seed=seed, mode=mode, land=land, workers=workers, scheduler=scheduler,
                       out=out, resume=resume, overwrite=overwrite, shard=shard)
    if report and o.out is None:
        raise ProfileError("report: needs out, the directory to write report.html into")
    pipeline = spec_for(prof, o.mode, land=o.land)
    ev = run_evaluation(
        prof, runs=o.runs, seed=o.seed, mode=o.mode, out_dir=o.out, workers=o.workers or os.cpu_count(),
        scheduler=o.scheduler, resume=o.resume, progress=progress, spec=pipeline, shard=o.shard,
    )
    res = EvaluationResult(profile=spec_, summary=ev.summary, details=ev.details, results=ev.results, out_dir=o.out,
                           wall_s=ev.wall_s, warnings=ev.warnings)
    if report and ev.summary is not None:
        res.write_report()
    return res


def merge(profile: str | Path | ProfileSpec, shards: Sequence[str | Path], out: str | Path, *,
          report: bool = False) -> EvaluationResult:
    """Merge the directories of the N shards of one campaign (evaluate_profile(..., shard="K/N")) into out: the single
    campaign's files, bit for bit (but details.json's wall_s: the shards' sum). ProfileError (one line naming the
    directory) unless they are the N complete shards of one campaign of this profile."""
    from approachsim.campaign.evaluation import merge_shards

    spec_ = load_profile(profile)
    out_p = Path(out)
    if out_p.exists() and not out_p.is_dir():
        raise ProfileError(f"--out: {str(out_p)!r} exists and is not a directory")
    dirs = [Path(d) for d in shards]
    if any(d.resolve() == out_p.resolve() for d in dirs):
        raise ProfileError(f"--out: {str(out_p)!r} is one of the shards; merge into another directory")
    jl = out_p / "runs.jsonl"
    if jl.is_file() and jl.stat().st_size > 0:
        raise ProfileError(f"--out: {str(out_p)!r} already holds a campaign; merge into another directory")
    ev = merge_shards(spec_.profile, dirs, out_p)
    res = EvaluationResult(profile=spec_, summary=ev.summary, details=ev.details, results=ev.results, out_dir=out_p,
                           wall_s=ev.wall_s)
    if report:
        res.write_report()
    return res


# ---- study -------------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class StudyResult:
    """A finished trade study: one evaluation per variant (the same seed and runs: common random numbers)."""

    name: str
    rows: list[dict]
    """One row per variant (study.csv's columns): variant, best_category, failed_runs, and per category
    (CATI, CATII, CATIII) meets and the lateral / vertical 1-sigma and 95 % figures, ft."""
    evaluations: dict[str, EvaluationResult] = field(repr=False)
    """Each variant's evaluation, by variant name."""
    out_dir: Path | None

    @property
    def table(self) -> pandas.DataFrame:
        """rows as a DataFrame indexed by variant."""
        return _pandas().DataFrame(self.rows).set_index("variant")

    @property
    def verdicts(self) -> dict[str, dict[str, str]]:
        """Per variant the verdict per category."""
        return {v: ev.verdicts for v, ev in self.evaluations.items()}

    def text(self) -> str:
        """The comparison table `approachsim study` prints."""
        from approachsim.campaign.study import comparison_table

        return comparison_table(self.rows)

    def figure(self) -> Figure:
        """The study figure: each variant's 1-sigma at every decision height against the limits."""
        from approachsim.report.evaluate import study_figure

        return study_figure(self.rows)


def study(
    base: str | Path | ProfileSpec,
    variants: Mapping[str, Mapping[str, Any]] | None = None,
    *,
    axes: Mapping[str, Sequence[Any]] | None = None,
    name: str | None = None,
    runs: int | None = None,
    seed: int | None = None,
    mode: str | None = None,
    out: str | Path | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
) -> StudyResult:
    """A trade study of `base` (what `approachsim study` runs): the full factorial over `axes` (dotted profile key ->
    list of values; variant names "key=value,...") and the explicit `variants` (name -> {dotted key: value}), every
    variant validated before anything runs and evaluated with the same seed and runs. out: each variant into
    out/<variant>/ and study.json, study.csv, study.png (None: in memory)."""
    from approachsim.campaign.study import MODES, make_study

    b = load_profile(base)
    runs = _checked_int(b.profile.run.runs if runs is None else runs, 1, MAX_RUNS, "runs")
    seed = _checked_int(b.profile.run.seed if seed is None else seed, 0, 2**63 - 1, "seed")
    mode = b.profile.run.mode if mode is None else mode
    if mode not in MODES:
        raise ProfileError(f"mode: must be one of {', '.join(MODES)}, got {mode!r}")
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise ProfileError(f"workers: must be in [1, {MAX_WORKERS}], got {workers}")
    if scheduler is not None:
        if not SCHEDULER_ADDRESS.match(str(scheduler)):
            raise ProfileError(f"scheduler: must be an address like tcp://host:8786, got {scheduler!r}")
        require_distributed("")
    explicit = [(str(n), list(s.items()), f"variants[{n!r}]") for n, s in (variants or {}).items()]
    st = make_study(name or f"{b.name}-study", dict(b.data), b.source,
                    axes={str(k): list(v) for k, v in (axes or {}).items()}, variants=explicit, runs=runs, seed=seed,
                    mode=mode)
    out_p = None if out is None else Path(out)
    if out_p is not None and out_p.exists() and not out_p.is_dir():
        raise ProfileError(f"out: {str(out_p)!r} exists and is not a directory")
    return _run_study(st, b, out_p, workers=workers, scheduler=scheduler, resume=resume, progress=progress)


def study_file(path: str | Path, *, out: str | Path, workers: int | None = None, scheduler: str | None = None,
               resume: bool = False, progress: bool = True) -> StudyResult:
    """A study file (TOML: a base profile, [axes] and [[variant]]; docs/profiles.md) run into out as `approachsim
    study` runs it (the command is a thin layer over this function): every variant into out/<variant>/, then
    study.json, study.csv and study.png."""
    from approachsim.campaign.study import load_study

    st = load_study(path)
    base = ProfileSpec.from_file(st.base) if st.base is not None else None
    return _run_study(st, base, Path(out), workers=workers, scheduler=scheduler, resume=resume, progress=progress)


def _run_study(st: Any, base: ProfileSpec | None, out_p: Path | None, *, workers: int | None, scheduler: str | None,
               resume: bool, progress: bool) -> StudyResult:
    from approachsim.campaign.pipeline import require_stages
    from approachsim.campaign.study import comparison_rows, evaluate_variants, write_study

    require_stages(st.mode)
    evs = evaluate_variants(st, out_p, workers=workers, scheduler=scheduler, resume=resume, progress=progress)
    rows = comparison_rows(st, [ev.summary for ev in evs])
    if out_p is not None:
        write_study(st, out_p, rows)
        from approachsim.report.evaluate import write_study_figure

        write_study_figure(out_p, rows)
    evals = {}
    for v, ev in zip(st.variants, evs, strict=True):
        data = _variant_data(base, v) if base is not None else {}
        vspec = ProfileSpec(data=data, source=None if base is None else base.source, profile=v.profile,
                            settings=(() if base is None else base.settings) + tuple(v.settings))
        evals[v.name] = EvaluationResult(profile=vspec, summary=ev.summary, details=ev.details, results=ev.results,
                                         out_dir=None if out_p is None else out_p / v.slug, wall_s=ev.wall_s,
                                         warnings=ev.warnings)
    return StudyResult(name=st.name, rows=rows, evaluations=evals, out_dir=out_p)


def _variant_data(base: ProfileSpec, v: Any) -> dict:
    data = copy.deepcopy(dict(base.data))
    for dotted, value in v.settings:
        _set_dotted(data, dotted, value)
    data["name"] = v.profile.name
    return data


# ---- integrity risk ----------------------------------------------------------------------------------------------


def check_risk(profile: Profile, *, modes: Sequence[str] | None, method: str, samples: int, max_calls: int | None,
               fault_free_runs: int, truths: int, seed: int | None, workers: int | None, sensor_modes: bool,
               second_level: bool, prefix: str = "") -> dict:
    """Validate integrity_risk's options (ProfileError naming the option, with prefix "--" as the command line
    names them); the keyword arguments of campaign.integrity_risk.integrity_risk."""
    from approachsim.campaign.integrity_risk import MODES, modes_for

    if method not in ("nais", "ce", "mc"):
        raise ProfileError(f"{prefix}method: must be nais, ce or mc, got {method!r}")
    if not 10 <= samples <= 1_000_000:
        raise ProfileError(f"{prefix}samples: must be in [10, 1000000], got {samples}")
    if max_calls is not None and max_calls < samples:
        raise ProfileError(f"{prefix}max-calls: must be at least {prefix}samples ({samples}), got {max_calls}")
    if not 2 <= fault_free_runs <= 100_000:
        raise ProfileError(f"{prefix}fault-free-runs: must be in [2, 100000], got {fault_free_runs}")
    if not 1 <= truths <= 1000:
        raise ProfileError(f"{prefix}truths: must be in [1, 1000], got {truths}")
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise ProfileError(f"{prefix}workers: must be in [1, {MAX_WORKERS}], got {workers}")
    seed = profile.run.seed if seed is None else seed
    if not 0 <= seed < 2**63:
        raise ProfileError(f"{prefix}seed: must be in [0, 2^63), got {seed}")
    names = None if modes is None else [m.strip() for m in modes if m.strip()]
    try:
        modes_for(profile, names)
    except ValueError as e:
        raise ProfileError(f"{prefix}modes: {e}") from None
    if profile.sensors.gnss is None:
        raise ProfileError("profile: integrity-risk needs a GPS receiver ([sensors.gnss]): the bank monitors GPS")
    if names is not None and not names:
        raise ProfileError(f"{prefix}modes: name at least one of {', '.join(MODES)}")
    return {"modes": names, "method": method, "samples": samples, "max_calls": max_calls,
            "fault_free_runs": fault_free_runs, "truths": truths, "seed": seed, "workers": workers,
            "sensor_modes": bool(sensor_modes), "second_level": bool(second_level)}


def plain(x: Any) -> Any:
    """JSON-ready: numpy scalars as Python numbers, nan and inf as None (the contract's strict JSON)."""
    if isinstance(x, dict):
        return {str(k): plain(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [plain(v) for v in x]
    if isinstance(x, bool | str) or x is None:
        return x
    try:
        f = float(x)
    except (TypeError, ValueError):
        return str(x)
    if not math.isfinite(f):
        return None
    return int(f) if isinstance(x, int) else f


def integrity_risk(
    profile: str | Path | ProfileSpec,
    *,
    modes: Sequence[str] | None = None,
    method: str = "nais",
    samples: int = 200,
    max_calls: int | None = None,
    fault_free_runs: int = 100,
    truths: int = 4,
    seed: int | None = None,
    workers: int | None = None,
    sensor_modes: bool = False,
    second_level: bool = False,
    out: str | Path | None = None,
    log: Callable[[str], None] | None = None,
) -> dict:
    """P(HMI) per category by importance sampling over the fault modes (what `approachsim integrity-risk` runs;
    docs/integrity.md): integrity_risk.json's content as plain data (categories.<CAT>.p_hmi, p_hmi_upper, verdict
    "shown" | "not shown" | "exceeds": the specific risk, each mode's worst magnitude / onset bin; the average beside
    it as p_hmi_average_upper, verdict_average; docs/contract.md), also written to out/integrity_risk.json when out
    is given. log: a function given each progress line (default: none)."""
    import json

    from approachsim.campaign.integrity_risk import integrity_risk as run_risk

    spec_ = load_profile(profile)
    kw = check_risk(spec_.profile, modes=modes, method=method, samples=samples, max_calls=max_calls,
                    fault_free_runs=fault_free_runs, truths=truths, seed=seed, workers=workers,
                    sensor_modes=sensor_modes, second_level=second_level)
    out_p = None if out is None else Path(out)
    if out_p is not None and out_p.exists() and not out_p.is_dir():
        raise ProfileError(f"out: {str(out_p)!r} exists and is not a directory")
    res = plain(run_risk(spec_.profile, log=log, **kw))
    if out_p is not None:
        out_p.mkdir(parents=True, exist_ok=True)
        (out_p / "integrity_risk.json").write_text(json.dumps(res, indent=1, allow_nan=False) + "\n")
    return res
