"""approachsim: does this aircraft's navigation system meet CAT I, II or III precision-approach accuracy?

A JSBSim transport jet flies the glidepath (truth); sensor models corrupt the truth; a strapdown INS with
a baro damping loop and an error-state EKF estimates the state; the autopilot flies on that estimate; the
evaluator scores navigation error at the decision heights against the FAA/ICAO limits over Monte Carlo runs.
"""

__version__ = "0.1.0"
