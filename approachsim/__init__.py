"""approachsim: does this aircraft's navigation system meet CAT I, II or III precision-approach accuracy?

A JSBSim transport jet flies the glidepath (truth); sensor models corrupt the truth; a strapdown INS with
a baro damping loop and an error-state EKF estimates the state; the autopilot flies on that estimate; the
evaluator scores navigation error at the decision heights against the FAA/ICAO limits over Monte Carlo runs.

The Python API (approachsim/api.py, docs/api.md) is available here, loaded on first use so that `import approachsim`
stays light:

    import approachsim as asim
    nav04 = asim.load_profile("default").with_settings({"sensors.imu.grade": "nav-0.4"})
    ev = asim.evaluate_profile(nav04, runs=20)
    ev.verdicts, ev.summary, ev.runs, ev.figure("errors_vs_height")
"""

__version__ = "0.1.0"

API = ("EvaluationResult", "ProfileError", "ProfileSpec", "StudyResult", "evaluate_profile", "integrity_risk",
       "load_profile", "merge", "shipped_profiles", "study", "study_file")
"""The names of approachsim.api exported here (approachsim.api.__all__)."""


def __getattr__(name: str) -> object:
    """The API's names, imported from approachsim.api when first asked for (PEP 562)."""
    if name in API:
        import importlib

        return getattr(importlib.import_module("approachsim.api"), name)
    raise AttributeError(f"module 'approachsim' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *API])
