"""GPS: nominal constellation (constellation.py), receiver clock (clock.py), pseudoranges (receiver.py), the
elevation scaling of their errors (elevation.py), GBAS corrections (gbas.py), carrier phase (carrier.py)."""

from approachsim.sensors.gnss.clock import ClockModel
from approachsim.sensors.gnss.constellation import Constellation
from approachsim.sensors.gnss.receiver import CODE_PRESETS, GnssErrorBudget, GnssReceiver

__all__ = ["CODE_PRESETS", "ClockModel", "Constellation", "GnssErrorBudget", "GnssReceiver"]
