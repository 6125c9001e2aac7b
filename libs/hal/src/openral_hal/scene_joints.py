"""Reading a manifest's joints out of a scene backend that does not speak the manifest.

A native scene reports its robot's joint state in manifest units itself. Another backend
(robosuite) does not: its MuJoCo data is read here by joint name, raw (positions,
velocities, actuator efforts at each joint's addresses), and a backend without MuJoCo
gives positions in ``obs.joints`` (zeros when absent; padded or cut to the manifest's
width), zero velocities and efforts.
"""

from __future__ import annotations

import logging
import time

import mujoco
import numpy as np
from openral_core.located import error_at
from openral_core.models import RobotDescription
from openral_mujoco.mjcf_model import is_scalar_joint
from openral_mujoco.name_resolution import resolve_joint_names
from openral_mujoco.state import FloatArray, JointStateSample
from openral_sim.rollout import Observation

from openral_hal.errors import HalError

_log = logging.getLogger(__name__)


class SceneJointReader:
    """The manifest's joints, read raw from a backend's MuJoCo data or observation."""

    def __init__(
        self, description: RobotDescription, mjcf_names: tuple[str, ...], backend: str
    ) -> None:
        """Read the joints of ``description`` (canonical names) found in a model under
        ``mjcf_names`` (the same order), from the backend named ``backend`` (for messages)."""
        self.description = description
        self.backend = backend
        self.joint_names = tuple(j.name for j in description.joints)
        self._mjcf_names = mjcf_names
        self._model: mujoco.MjModel | None = None
        self._qpos = self._dof = np.zeros(0, dtype=np.intp)
        self._warned_width = False

    def locate(self, model: mujoco.MjModel) -> None:
        """Find every joint in ``model`` (again when a backend rebuilt its model).

        Raises:
            ManifestError: At the manifest's joints: a joint is missing, or is not a hinge
                or slide joint.
        """
        joint = mujoco.mjtObj.mjOBJ_JOINT
        available = [mujoco.mj_id2name(model, joint, i) for i in range(model.njnt)]
        try:
            resolved = resolve_joint_names(self._mjcf_names, [n for n in available if n])
        except HalError as error:  # the manifest's joints: say so at its joints list
            raise error_at(self.description, ("joints",), str(error)) from None
        ids = [mujoco.mj_name2id(model, joint, resolved[n]) for n in self._mjcf_names]
        bad = [
            resolved[n]
            for n, i in zip(self._mjcf_names, ids, strict=True)
            if not is_scalar_joint(model, i)
        ]
        if bad:
            message = (
                f"scene joints {', '.join(bad)} are not hinge or slide joints; a manifest "
                "joint must map to a one-value joint"
            )
            raise error_at(self.description, ("joints",), message)
        self._qpos = np.array([model.jnt_qposadr[i] for i in ids], dtype=np.intp)
        self._dof = np.array([model.jnt_dofadr[i] for i in ids], dtype=np.intp)
        self._model = model

    def read(
        self, handles: tuple[mujoco.MjModel, mujoco.MjData] | None, obs: Observation
    ) -> JointStateSample:
        """The joint state from the backend's live (model, data), or from ``obs`` when it
        has no MuJoCo."""
        if handles is None:
            zeros = np.zeros(len(self.joint_names))
            return JointStateSample(
                names=self.joint_names,
                positions=self._positions_from_obs(obs),
                velocities=zeros,
                efforts=zeros.copy(),
                stamp_ns=time.monotonic_ns(),
            )
        model, data = handles
        if model is not self._model:
            self.locate(model)
        return JointStateSample(
            names=self.joint_names,
            positions=data.qpos[self._qpos].astype(np.float64),
            velocities=data.qvel[self._dof].astype(np.float64),
            efforts=data.qfrc_actuator[self._dof].astype(np.float64),
            stamp_ns=time.monotonic_ns(),
            sim_time_s=float(data.time),
        )

    def _positions_from_obs(self, obs: Observation) -> FloatArray:
        count = len(self.joint_names)
        if obs.joints is None:
            return np.zeros(count)
        values = np.asarray(obs.joints.positions, dtype=np.float64).ravel()
        if values.size != count:
            if not self._warned_width:
                _log.warning(
                    "%s reports %d joint positions but the manifest of %s has %d joints; "
                    "padding with zeros or truncating",
                    self.backend,
                    values.size,
                    self.description.name,
                    count,
                )
                self._warned_width = True
            values = np.concatenate([values, np.zeros(max(0, count - values.size))])[:count]
        return values
