"""Scene step rates: env.step per second with cameras rendering, per backend.

Robosuite half only for now: Lift with the Panda, the agentview and wrist cameras rendered
offscreen at ``width`` x ``height``, zero actions (the default OSC controller holds the pose).
"""

from __future__ import annotations

import argparse
import os
import time

os.environ.setdefault("MUJOCO_GL", "egl")

import numpy as np

CAMERAS = ("agentview", "wrist")


def robosuite_steps_per_s(steps: int, width: int, height: int) -> float:
    """``SimRollout.step`` calls per second of robosuite Lift + Panda with two cameras.

    Environment construction, the first reset and a short warm-up (numba compiles robosuite's
    controller math on first use) are left out of the timing.
    """
    from openral_sim.robosuite_backend import RobosuiteRollout

    rollout = RobosuiteRollout("Lift", "Panda", CAMERAS, width, height, horizon=steps + 10)
    try:
        rollout.reset(0)
        action = np.zeros(rollout.action_dim)
        for _ in range(5):
            rollout.step(action)
        start = time.perf_counter()
        for _ in range(steps):
            rollout.step(action)
        return steps / (time.perf_counter() - start)
    finally:
        rollout.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=100, help="timed env steps")
    parser.add_argument("--size", type=int, default=128, help="image width and height [px]")
    args = parser.parse_args()
    rate = robosuite_steps_per_s(args.steps, args.size, args.size)
    print(f"robosuite Lift+Panda, {len(CAMERAS)} cameras at {args.size} px: {rate:.1f} steps/s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
