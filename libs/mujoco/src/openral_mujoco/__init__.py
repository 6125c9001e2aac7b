"""The MuJoCo layer under the HAL and the scenes: model facts, MJCF resolution, the action
contract (validation, grippers, slew, PD law) and offscreen-rendering choices.

Imports nothing heavy here: :mod:`openral_mujoco.display` must run before ``import mujoco``.
"""
