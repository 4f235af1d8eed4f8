"""Integrity formulas: requirements per category, solution-separation protection levels and tests, fault detection
and exclusion thresholds, rare-event estimators. Plain arrays in and out, below nav/ and evaluate/ (which use them);
the runs that use them (the sub-filter bank, its campaign scores, the integrity-risk study) are in campaign/."""
