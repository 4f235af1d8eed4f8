"""Evaluation: navigation error at decision heights against FAA/ICAO limits, protection levels, verdicts."""
