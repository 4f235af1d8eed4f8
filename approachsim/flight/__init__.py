"""Truth: JSBSim flies the aircraft down the glidepath under a Python autopilot; the Truth record."""
