"""The command line as a new user meets it: --version, a description and an example in every help, navigate's
help naming the filters, study given a profile, --scheduler without dask.distributed, --resume with nothing to
resume. Nothing here flies."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from approachsim.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = str(ROOT / "profiles" / "default.toml")
COMMANDS = ("fly", "sense", "navigate", "evaluate", "merge", "integrity-risk", "study", "regress", "profiles")


def _one_line(err: str, needle: str) -> None:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert needle in lines[0], lines[0]
    assert "Traceback" not in err


def test_version(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    out = capsys.readouterr().out.strip()
    assert out.startswith("approachsim ") and out.split()[1][0].isdigit(), out


def test_every_command_listed_in_the_top_help_exists():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert set(COMMANDS) <= set(sub.choices)
    for name in sub.choices:  # each one builds its own help
        sub.choices[name].format_help()


@pytest.mark.parametrize("command", COMMANDS)
def test_help_has_a_description_and_an_example(command, capsys):
    with pytest.raises(SystemExit) as e:
        main([command, "--help"])
    assert e.value.code == 0
    text = capsys.readouterr().out
    usage, _, rest = text.partition("\n\n")
    description = rest.split("\n\n")[0]
    assert len(description.split()) >= 8, f"{command}: no description:\n{text}"
    assert "example" in text and f"approachsim {command}" in text.split("example")[-1], text


def test_navigate_help_lists_every_filter(capsys):
    from approachsim.nav.registry import FILTERS

    with pytest.raises(SystemExit):
        main(["navigate", "--help"])
    text = capsys.readouterr().out
    for name in FILTERS:
        assert name in text, name


def test_study_given_a_profile_says_what_a_study_needs(tmp_path, capsys):
    assert main(["study", DEFAULT, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    _one_line(err, "is a profile, not a study file")
    assert "[axes]" in err and "approachsim evaluate" in err
    assert not (tmp_path / "o").exists()


def test_study_with_a_shipped_base_profile_name_loads(tmp_path):
    from approachsim.campaign.study import load_study
    from approachsim.resources import PROFILES_DIR

    f = tmp_path / "s.toml"
    f.write_text('profile = "hot-high-crosswind"\nruns = 2\n[axes]\n"environment.wind_speed_kt" = [0, 10]\n')
    study = load_study(f)
    assert study.base == PROFILES_DIR / "hot-high-crosswind.toml" and len(study.variants) == 2


@pytest.mark.parametrize("command", ["evaluate", "study"])
def test_resume_with_nothing_to_resume_is_an_error(tmp_path, capsys, command):
    target = DEFAULT if command == "evaluate" else str(ROOT / "studies" / "ins-grade-x-aids.toml")
    assert main([command, target, "--out", str(tmp_path / "missing"), "--resume"]) == 2
    _one_line(capsys.readouterr().err, "--resume: no ")
    assert not (tmp_path / "missing").exists()


@pytest.mark.parametrize("command", ["evaluate", "study"])
def test_scheduler_without_distributed_names_the_extra(tmp_path, command):
    target = DEFAULT if command == "evaluate" else str(ROOT / "studies" / "ins-grade-x-aids.toml")
    code = (
        "import sys; sys.modules['distributed'] = None\n"  # as if the dask extra were not installed
        "from approachsim.cli import main\n"
        f"raise SystemExit(main({[command, target, '--out', str(tmp_path / 'o'), '--scheduler', 'tcp://h:8786']!r}))"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert p.returncode == 2, p.stderr
    _one_line(p.stderr, "pip install approachsim[dask]")
