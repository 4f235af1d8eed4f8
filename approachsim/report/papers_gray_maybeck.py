"""Figure of the Gray & Maybeck reproduction: time-averaged RMS error per case and error state (Tables 3-6's
numbers before they are averaged over the INS grades), bars per case, one panel per state."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

STATES = ("latitude", "longitude", "altitude", "clock_bias")


def write_figures(data: dict[str, Any], out_dir: Path) -> list[str]:
    """Write gray-maybeck_cases.png into out_dir from compute()'s data; return the file names."""
    per_case = data["per_case"]
    if not per_case:
        return []
    names = [v["case"] for v in per_case.values()]
    fig, axes = plt.subplots(len(STATES), 1, figsize=(8, 8), sharex=True)
    x = np.arange(len(names))
    for ax, s in zip(axes, STATES, strict=True):
        y = [v["time_averaged_rms_ft"][s] for v in per_case.values()]
        y = [np.nan if v is None else v for v in y]
        colors = ["tab:blue" if v["radalt"] else "0.6" for v in per_case.values()]
        ax.bar(x, y, color=colors, edgecolor=["k" if v["pseudolite"] else "none" for v in per_case.values()])
        ax.set_ylabel(f"{s.replace('_', ' ')} (ft)")
        ax.grid(axis="y", alpha=0.3)
    axes[-1].set_xticks(x, names)
    axes[-1].set_xlabel("case (blue: radar altimeter; outlined: pseudolite)")
    axes[0].set_title("Time-averaged RMS true error per case (ours)")
    fig.tight_layout()
    name = "gray-maybeck_cases.png"
    fig.savefig(Path(out_dir) / name, dpi=110)
    plt.close(fig)
    return [name]
