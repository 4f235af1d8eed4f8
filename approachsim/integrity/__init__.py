"""Integrity: requirements per category, solution-separation protection levels, fault detection and exclusion
thresholds, and the integrity scoring (availability, misleading information, time to alert)."""
