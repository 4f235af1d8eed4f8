"""The sensor models' compiled error application (approachsim/core/__init__.py lists the modules)."""
