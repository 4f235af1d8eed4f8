"""The navigation stage's compiled arithmetic (approachsim/core/__init__.py lists the modules)."""
