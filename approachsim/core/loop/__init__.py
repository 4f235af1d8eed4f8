"""The compiled flight loop and the closed loop inside it (approachsim/core/__init__.py lists the modules)."""
