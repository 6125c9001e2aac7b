"""Scene backends: a deploy-scene file becomes a SimRollout that owns physics and pixels."""
