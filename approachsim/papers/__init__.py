"""Reproductions of the seed papers on their own small models, side by side with their published tables."""
