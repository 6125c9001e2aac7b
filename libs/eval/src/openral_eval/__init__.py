"""Evaluating policies on simulated scenes: the policy registry, episodes and sweeps.

Between the HAL and the apps: an episode drives a scene through the same HAL contract as
``deploy sim`` (:class:`~openral_hal.sim_attached.SimAttachedHAL`), without ROS.
"""
