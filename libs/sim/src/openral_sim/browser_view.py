"""A browser view of a running MuJoCo scene: Rerun's web viewer, fed every tick.

:class:`BrowserView` serves Rerun's web viewer (HTML and Wasm from the ``rerun-sdk`` wheel,
nothing fetched) and a data stream the page connects to, then draws what
:mod:`openral_sim.view_geometry` reads from the model: the robot's and the scene's bodies as
meshes and primitives along the frame tree, posed from ``data`` at each :meth:`pose`; camera
images and depth frames; one plot line per joint and per action slot, all on the simulated
time line ``sim_time``. The page and the data stream listen on ``host`` only (127.0.0.1 by
default): the data stream is Rerun's, the page is served by :mod:`openral_sim.viewer_page`
(Rerun 0.41's own page server listens on every interface). Both stop at :meth:`close`.

Logging is cheap (Rerun batches and sends on threads of its own); :meth:`pose` skips ticks
closer than ``1 / max_rate_hz`` in simulated time, so a 1 kHz loop sends at most 30 poses a
second by default.
"""

from __future__ import annotations

import socket
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt
import rerun as rr  # an optional extra (`openral[view]`): import this module only for a view
import rerun.blueprint as rrb

from openral_sim.view_geometry import WORLD, BodyTree, Geom, GeomShape, body_tree, relative_poses
from openral_sim.view_geometry import visible_geoms as _visible_geoms
from openral_sim.viewer_page import PageServer, ViewUnavailable, viewer_files

AXIS_LENGTH_M = 0.1
"""Length of the axes drawn at a frame of :meth:`BrowserView.transform` [m]."""


@dataclass(frozen=True)
class ViewPorts:
    """Where the view listens: the page on ``web``, the data stream on ``host:web + 1``."""

    web: int = 9090
    host: str = "127.0.0.1"

    @property
    def data(self) -> int:
        """The data stream's port (the page's plus one)."""
        return self.web + 1

    @property
    def url(self) -> str:
        """The page to open; it connects to the data stream by itself."""
        stream = f"rerun%2Bhttp%3A%2F%2F{self.host}%3A{self.data}%2Fproxy"
        return f"http://{self.host}:{self.web}/?url={stream}"


class BrowserView:
    """Rerun's web viewer showing one MuJoCo scene (see the module doc)."""

    def __init__(
        self,
        model: mujoco.MjModel | None,
        *,
        title: str,
        cameras: Sequence[str] = (),
        ports: ViewPorts | None = None,
        max_rate_hz: float = 30.0,
    ) -> None:
        """Start serving and draw the model's geometry.

        Args:
            model: The scene's model (the view keeps its body tree and geometry); None
                for a view without one (a recorded bag: frames by :meth:`transform`).
            title: Shown as the recording's name.
            cameras: Camera names whose images get a panel, in this order.
            ports: Where to listen (default :class:`ViewPorts`).
            max_rate_hz: Most poses sent per second of simulated time [Hz].

        Raises:
            ViewUnavailable: A port is taken, or Rerun's page files cannot be copied
                (:func:`~openral_sim.viewer_page.viewer_files`).
        """
        self.ports = ports or ViewPorts()
        self.tree = (
            body_tree(model) if model is not None else BodyTree((WORLD,), np.zeros(1, np.int32), ())
        )
        self._period_s = 1.0 / max_rate_hz
        self._last_s = -np.inf
        self._posed_static = False
        for port in (self.ports.web, self.ports.data):
            _check_free(self.ports.host, port)
        self._page = PageServer(viewer_files(), self.ports.host, self.ports.web)
        self.stream = rr.RecordingStream("openral", recording_id=title)
        self.stream.send_recording_name(title)
        try:
            self.stream.set_sinks(rr.GrpcServerSink(bind_ip=self.ports.host, port=self.ports.data))
        except Exception as error:  # Rerun raises plain errors for a port in use
            self._page.close()
            raise ViewUnavailable(f"the view cannot listen: {error}") from None
        self.stream.send_blueprint(_layout(cameras, _eye(model) if model is not None else None))
        self.stream.log(WORLD, rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        for geom in _visible_geoms(model, self.tree) if model is not None else ():
            self.stream.log(geom.path, *_archetypes(geom), static=True)

    def pose(self, data: mujoco.MjData, time_s: float) -> bool:
        """Send the bodies' poses of this tick; False when skipped (too soon after the
        last one sent, in simulated time)."""
        if time_s - self._last_s < self._period_s and time_s >= self._last_s:
            return False
        self._last_s = time_s
        if not self._posed_static:  # bodies fixed to their parent: once, for good
            fixed = tuple(b for b in range(1, len(self.tree.paths)) if b not in self.tree.moving)
            self._send_poses(data, fixed, static=True)
            self._posed_static = True
        self.stream.set_time("sim_time", duration=time_s)
        self._send_poses(data, self.tree.moving, static=False)
        return True

    def _send_poses(self, data: mujoco.MjData, bodies: tuple[int, ...], *, static: bool) -> None:
        if not bodies:
            return
        translations, quaternions = relative_poses(data, self.tree, bodies)
        for body, t, q in zip(bodies, translations, quaternions, strict=True):
            transform = rr.Transform3D(translation=t, quaternion=rr.Quaternion(xyzw=q))
            self.stream.log(self.tree.paths[body], transform, static=static)

    def transform(
        self,
        path: str,
        translation: Sequence[float],
        quaternion_xyzw: Sequence[float],
        time_s: float | None,
    ) -> None:
        """A frame's pose in its parent (the entity above ``path``), drawn as axes; at
        ``time_s`` on the time line, or for good when it is None (a static transform)."""
        if time_s is not None:
            self.stream.set_time("sim_time", duration=time_s)
        rotation = rr.Quaternion(xyzw=quaternion_xyzw)
        placed = rr.Transform3D(translation=translation, quaternion=rotation)
        self.stream.log(path, placed, rr.TransformAxes3D(AXIS_LENGTH_M), static=time_s is None)

    def plot(self, group: str, values: Mapping[str, float], time_s: float) -> None:
        """One point per name on the plot ``group`` (``joints``, ``action``)."""
        self.stream.set_time("sim_time", duration=time_s)
        for name, value in values.items():
            self.stream.log(f"{group}/{name}", rr.Scalars(float(value)))

    def image(self, camera: str, rgb: npt.NDArray[np.uint8], time_s: float) -> None:
        """A camera's RGB frame (height x width x 3)."""
        self.stream.set_time("sim_time", duration=time_s)
        self.stream.log(f"cameras/{camera}", rr.Image(rgb))

    def depth(self, camera: str, depth_m: npt.NDArray[np.floating], time_s: float) -> None:
        """A depth camera's frame [m] (height x width)."""
        self.stream.set_time("sim_time", duration=time_s)
        self.stream.log(f"cameras/{camera}/depth", rr.DepthImage(depth_m, meter=1.0))

    def close(self) -> None:
        """Flush what was logged and stop serving the data stream and the page."""
        try:
            self.stream.flush()
            self.stream.disconnect()
        finally:
            self._page.close()


def _check_free(host: str, port: int) -> None:
    """Raise :class:`ViewUnavailable` when ``host:port`` is taken (Rerun only logs it, from
    a thread of its own, and serves nothing)."""
    with socket.socket() as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError as error:
            raise ViewUnavailable(
                f"the view cannot listen on {host}:{port} ({error.strerror})"
            ) from None


def _eye(model: mujoco.MjModel) -> rrb.EyeControls3D:
    """Where MuJoCo's own viewer starts: looking at the model's centre from 1.5 extents
    away, at the model's default azimuth and elevation (``<visual><global>``)."""
    azimuth, elevation = np.radians([model.vis.global_.azimuth, model.vis.global_.elevation])
    forward = np.array(
        [
            np.cos(elevation) * np.cos(azimuth),
            np.cos(elevation) * np.sin(azimuth),
            np.sin(elevation),
        ]
    )
    centre = np.asarray(model.stat.center, dtype=np.float64)
    position = centre - 1.5 * float(model.stat.extent) * forward
    return rrb.EyeControls3D(position=position, look_target=centre, eye_up=[0.0, 0.0, 1.0])


def _layout(cameras: Sequence[str], eye: rrb.EyeControls3D | None) -> rrb.Blueprint:
    """The 3-D scene on the left; camera panels and the plots on the right."""
    panels = [rrb.Spatial2DView(origin=f"cameras/{c}", name=c) for c in cameras]
    plots = [rrb.TimeSeriesView(origin=g, name=g) for g in ("joints", "action")]
    scene = rrb.Spatial3DView(origin="world", name="scene", eye_controls=eye)
    right = rrb.Vertical(*panels, *plots)
    return rrb.Blueprint(rrb.Horizontal(scene, right, column_shares=[3, 2]), collapse_panels=True)


def _archetypes(geom: Geom) -> list[rr.AsComponents]:
    """The Rerun archetypes drawing ``geom``: its pose in the body frame, then its shape."""
    rotation = rr.Quaternion(xyzw=geom.quaternion_xyzw)
    placed = rr.Transform3D(translation=geom.position, quaternion=rotation)
    size, color = geom.size, [geom.rgba]
    shape: rr.AsComponents
    if geom.shape == GeomShape.MESH:
        assert geom.vertices is not None and geom.faces is not None
        shape = rr.Mesh3D(
            vertex_positions=geom.vertices, triangle_indices=geom.faces, albedo_factor=geom.rgba
        )
    elif geom.shape == GeomShape.BOX:
        shape = rr.Boxes3D(half_sizes=[size], colors=color, fill_mode="solid")
    elif geom.shape in (GeomShape.SPHERE, GeomShape.ELLIPSOID):
        radii = [size[0]] * 3 if geom.shape == GeomShape.SPHERE else size
        shape = rr.Ellipsoids3D(half_sizes=[radii], colors=color, fill_mode="solid")
    elif geom.shape == GeomShape.CAPSULE:  # Rerun's capsule starts at its origin, along +z
        shape = rr.Capsules3D(
            lengths=[2 * size[1]], radii=[size[0]], translations=[[0, 0, -size[1]]], colors=color
        )
    elif geom.shape == GeomShape.CYLINDER:
        shape = rr.Cylinders3D(
            lengths=[2 * size[1]], radii=[size[0]], colors=color, fill_mode="solid"
        )
    else:  # a plane: a thin box of its half-sizes (an infinite plane drawn 5 m across)
        half = [size[0] or 2.5, size[1] or 2.5, 1e-3]
        shape = rr.Boxes3D(
            half_sizes=[half], centers=[[0, 0, -1e-3]], colors=color, fill_mode="solid"
        )
    return [placed, shape]


__all__ = ["BodyTree", "BrowserView", "ViewPorts", "ViewUnavailable"]
