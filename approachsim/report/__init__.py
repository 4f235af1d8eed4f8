"""Figures and report pages (the only stage that imports matplotlib)."""
