"""docs/profiles.md is generated from the parsers (tools/gen_profiles_doc.py): it is current, it lists every key
the parsers read, and a key without a description fails the generator."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _tool():
    spec = importlib.util.spec_from_file_location("gen_profiles_doc", ROOT / "tools" / "gen_profiles_doc.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["gen_profiles_doc"] = mod
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def generated() -> str:
    from approachsim.config import Section

    saved = {k: Section.__dict__[k] for k in ("raw", "number", "integer", "boolean", "string", "numbers",
                                              "section", "sections")}
    try:
        yield _tool().generate()
    finally:
        for k, v in saved.items():
            setattr(Section, k, v)  # the recorder patches Section: undo it for the other tests


def test_docs_profiles_md_is_current(generated):
    assert (ROOT / "docs" / "profiles.md").read_text(encoding="utf-8") == generated, (
        "run: python tools/gen_profiles_doc.py"
    )


def test_every_documented_table_and_key_appears(generated):
    for needle in ("### [runway]", "### [[faults]]", "### [evaluation]", "### [terrain]", "### [nav.initial_error]",
                   "### [[sensors.pseudolite.units]]", "## Study files", "### [[variant]]", "### [autopilot]",
                   "| `threshold_lat_deg` | number | deg | **required** | [-85, 85] |",
                   "| `glidepath_deg` | number | deg | `3` | [1, 10] |", "`robust-ud-huber`", "`nav-4.0`"):
        assert needle in generated, needle


def test_a_key_without_a_description_fails():
    tool = sys.modules.get("gen_profiles_doc") or _tool()
    keys = {"profile": [tool.Key(table="runway", key="new_key_ft", kind="number")], "study": [], "aircraft": []}
    meta = {"intro": {"text": "", "profile_heading": "", "study_heading": "", "aircraft_heading": ""},
            "profile": {}, "study": {}, "aircraft": {"stale": {"doc": "x"}}}
    with pytest.raises(SystemExit, match=r"runway\.new_key_ft: no entry.*stale: entry .* do not read"):
        tool.render(keys, meta)
