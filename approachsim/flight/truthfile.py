"""The truth file: a Truth record saved as NPZ (one array per field) plus a JSON schema sidecar.

Users open it without approachsim:

    import json, numpy as np
    z = np.load("truth.npz")            # z["t_s"], z["r_rwy"], z["f_body"], ...
    schema = json.load(open("truth.json"))

truth.npz holds every Truth field (float64, time on axis 0; see docs/truth.md for the table) plus the runway
frame as `runway_frame` = [threshold lat (rad), lon (rad), ellipsoid height (m), heading (rad)].
truth.json ("schema": "approachsim.truth/1") lists each array with its shape, unit, frame and description,
and carries run metadata (profile, seed, run). The NPZ is written uncompressed with fixed member order and
no timestamps, so the same run gives a bit-identical file.
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np

from approachsim import records
from approachsim.geo import RunwayFrame
from approachsim.records import Truth

SCHEMA = "approachsim.truth/1"

UNITS = {
    "t_s": "s", "lat_rad": "rad", "lon_rad": "rad", "h_m": "m", "r_ecef": "m", "v_ned": "m/s", "q_nb": "1",
    "euler_rad": "rad", "w_ib_body": "rad/s", "f_body": "m/s^2", "p_static_pa": "Pa", "t_air_k": "K",
    "h_agl_m": "m", "r_rwy": "m", "gs_dev_m": "m", "loc_dev_m": "m", "controls": "1", "airspeed_mps": "m/s",
}
"""Unit of each Truth array."""


def _descriptions() -> dict[str, str]:
    """Each Truth field's docstring (the attribute docstrings of records.Truth, read from its source)."""
    import ast
    import inspect

    tree = ast.parse(inspect.getsource(records.Truth))
    body = tree.body[0].body  # type: ignore[attr-defined]
    out = {}
    for a, b in zip(body, body[1:], strict=False):
        if isinstance(a, ast.AnnAssign) and isinstance(b, ast.Expr) and isinstance(b.value, ast.Constant):
            out[a.target.id] = " ".join(str(b.value.value).split())  # type: ignore[union-attr]
    return out


def schema(truth: Truth, meta: dict[str, Any] | None = None) -> dict[str, Any]:
    """The JSON schema sidecar of a truth record."""
    desc = _descriptions()
    arrays = {
        name: {"shape": list(a.shape), "dtype": str(a.dtype), "unit": UNITS[name], "description": desc.get(name, "")}
        for name, a in truth.arrays().items()
    }
    arrays["runway_frame"] = {
        "shape": [4], "dtype": "float64", "unit": "rad, rad, m, rad",
        "description": "threshold geodetic latitude, longitude, ellipsoid height, true heading of the landing "
                       "direction: the runway frame r_rwy is in (x along, y right, z height above threshold)",
    }
    return {
        "schema": SCHEMA,
        "samples": len(truth),
        "time_axis": 0,
        "sampling": "row k is the state after JSBSim step k; f_body[k] and w_ib_body[k] are the specific force "
                    "and inertial rate that carry the state from row k to row k+1 (constant over the step)",
        "point": "kinematics are of the IMU location (aircraft file [imu])",
        "controls_columns": ["elevator (incl. pitch trim)", "aileron", "rudder", "throttle"],
        "meta": meta or {},
        "arrays": arrays,
    }


def save_truth(path: str | Path, truth: Truth, meta: dict[str, Any] | None = None) -> Path:
    """Write truth.npz (deterministic bytes) and its .json sidecar beside it; returns the NPZ path."""
    path = Path(path)
    rf = truth.runway
    members = dict(truth.arrays())
    members["runway_frame"] = np.array([rf.threshold_lat_rad, rf.threshold_lon_rad, rf.threshold_h_m, rf.heading_rad])
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_STORED) as zf:
        for name, arr in members.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            with zf.open(info, "w") as fh:
                np.lib.format.write_array(fh, np.ascontiguousarray(arr), allow_pickle=False)
    path.with_suffix(".json").write_text(json.dumps(schema(truth, meta), indent=2) + "\n", encoding="utf-8")
    return path


def load_truth(path: str | Path) -> Truth:
    """Read a truth.npz back into a Truth record."""
    with np.load(Path(path), allow_pickle=False) as z:
        rf = z["runway_frame"]
        names = [f.name for f in fields(Truth) if f.name != "runway"]
        return Truth(**{n: z[n] for n in names}, runway=RunwayFrame(*(float(v) for v in rf)))
