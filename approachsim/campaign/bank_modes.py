"""The fault modes of the integrity bank, by code: what one sub-filter leaves out.

A mode code is a GNSS channel index (>= 0, the receiver's channel), BARO_MODE, RADALT_MODE, or PSEUDOLITE_MODE - u
for pseudolite unit u. The bank (campaign/integrity_bank.py: `BankEpochs.channels`, bank_records) and its compiled
pass (campaign/bankpass.py: the copies' observations) read the same codes, so they live here, below both.
"""

from __future__ import annotations

BARO_MODE = -2
"""Mode code of the baro (a sub-filter without it)."""
RADALT_MODE = -3
"""Mode code of the radar altimeter."""
PSEUDOLITE_MODE = -10
"""Mode code of pseudolite unit 0; unit u is PSEUDOLITE_MODE - u."""


def mode_name(code: int) -> str:
    """A mode code's source: "gnss <channel>", "baro", "radalt" or "pseudolite <unit>"."""
    if code >= 0:
        return f"gnss {code}"
    if code == BARO_MODE:
        return "baro"
    if code == RADALT_MODE:
        return "radalt"
    return f"pseudolite {PSEUDOLITE_MODE - code}"
