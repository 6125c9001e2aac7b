"""Bridges between a simulated scene and the outside world (idle stepping, sensors)."""
