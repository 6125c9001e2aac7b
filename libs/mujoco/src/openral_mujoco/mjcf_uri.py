"""Resolve a manifest's ``sim.mjcf_uri`` to an MJCF file on disk, offline and confined.

Schemes:

- ``file:<path>``: relative to the manifest's folder, and inside it.
- ``pkg:<distribution>/<path>``: a file shipped inside an installed distribution, found
  through its installed-files record (``importlib.metadata``); ``<path>`` is matched against
  the end of each recorded path, so data files installed outside site-packages resolve too
  (``pkg:openarm-mujoco/openarm_mujoco/v2/openarm_bimanual.xml`` finds
  ``share/openarm_mujoco/v2/openarm_bimanual.xml``).
- ``robosuite:<path>`` (deprecated): ``robosuite/models/assets/<path>`` of the installed
  robosuite, the same file as ``pkg:robosuite/robosuite/models/assets/<path>``. It still
  resolves; ``openral robot check`` reports each use with its replacement
  (:func:`deprecated_uris`).

``<distribution>`` must be a distribution name (PEP 508: letters, digits, ``.``, ``_``, ``-``,
starting and ending with a letter or digit) and a ``pkg:``/``robosuite:`` ``<path>`` must
have no empty, ``.`` or ``..`` part; anything else is refused before any look-up.

Each resolution has a confinement root (:class:`~openral_mujoco.mjcf_confinement.Confinement`):
the robot's folder for ``file:``, the folder holding the distribution's files next to the
model for the others. The model, and every file it includes or loads, must lie inside it
(symlinks resolved) unless ``OPENRAL_ALLOW_OUTSIDE=1`` or the caller's ``allow_outside``
allows otherwise; :func:`resolve_mjcf_uri` returns only files that passed
:func:`~openral_mujoco.mjcf_confinement.check_mjcf_files`. Nothing is ever downloaded or imported.
Every failure is one :class:`MjcfUriError` that names the manifest, the URI and what to do.
"""

from __future__ import annotations

import importlib.metadata as metadata
import os
import re
from pathlib import Path, PurePosixPath

from openral_core.errors import OpenralError
from openral_core.located import error_at, source_file
from openral_core.models import RobotDescription
from openral_core.registry import manifest_path

from openral_mujoco.mjcf_confinement import (
    ALLOW_OUTSIDE_ENV,
    Confinement,
    MjcfConfinementError,
    check_mjcf_files,
    outside_allowed,
)

SCHEMES = ("file", "pkg", "robosuite")
"""Every scheme :func:`resolve_mjcf_uri` understands."""

DISTRIBUTION = "openral"
"""Our own distribution, whose extras name the robot model packages."""

PKG_FORM = "'pkg:<distribution>/<path inside it>'"
"""How a ``pkg:`` URI is written, for messages."""
_DISTRIBUTION_NAME = re.compile(r"[A-Za-z0-9](?:[A-Za-z0-9._-]*[A-Za-z0-9])?")
"""A distribution name as PEP 508 spells it."""


class MjcfUriError(OpenralError):
    """An ``mjcf_uri`` that cannot be turned into a readable, confined MJCF file."""

    def __init__(self, uri: str, problem: str, manifest_dir: Path | None = None) -> None:
        self.uri = uri
        self.problem = problem
        where = f"{manifest_dir / 'robot.yaml'}: " if manifest_dir is not None else ""
        super().__init__(f"{where}sim.mjcf_uri {uri!r}: {problem}")


def resolve_mjcf_uri(
    uri: str, manifest_dir: Path | None = None, *, allow_outside: bool = False
) -> Path:
    """The MJCF file ``uri`` names, checked to stay (with its includes and assets) confined.

    Args:
        uri: A ``<scheme>:<rest>`` string (see the module docstring).
        manifest_dir: Folder of the manifest, for ``file:`` paths and messages.
        allow_outside: Let the model and its files lie anywhere, for this call (as
            ``OPENRAL_ALLOW_OUTSIDE=1`` does for every call).

    Raises:
        MjcfUriError: Unknown scheme, package not installed, file missing, a file outside
            the confinement root, or XML that cannot be read safely.
    """
    path, confinement = locate_mjcf_uri(uri, manifest_dir)
    allowed = outside_allowed(allow_outside)
    if not allowed and (confinement is None or not confinement.contains(path)):
        where = f"outside {confinement}" if confinement else "with no robot folder to keep it in"
        raise MjcfUriError(
            uri,
            f"resolves to {os.path.realpath(path)}, {where}; set {ALLOW_OUTSIDE_ENV}=1 to allow it",
            manifest_dir,
        )
    if not path.is_file():
        raise MjcfUriError(uri, f"resolved to {path}, which is not a file", manifest_dir)
    if not allowed and confinement is not None:
        try:
            check_mjcf_files(path, confinement)
        except MjcfConfinementError as error:
            raise MjcfUriError(uri, str(error), manifest_dir) from None
    return path


def robot_model_file(robot: RobotDescription, manifest_dir: Path | None = None) -> Path:
    """The checked MJCF file of ``robot``'s ``sim.mjcf_uri``.

    Args:
        robot: A manifest with a ``sim`` block.
        manifest_dir: Its folder; defaults to the folder of the file it was loaded from,
            else ``robots/<name>/``.

    Raises:
        ManifestError: At ``sim.mjcf_uri`` of the manifest, saying why the URI does not
            give a usable file (see :func:`resolve_mjcf_uri`).
    """
    if robot.sim is None:
        raise error_at(robot, ("sim",), "the robot has no sim block; it has no model")
    return resolve_manifest_uri(robot, robot.sim.mjcf_uri, ("sim", "mjcf_uri"), manifest_dir)


def resolve_manifest_uri(
    robot: RobotDescription, uri: str, field: tuple[str, ...], manifest_dir: Path | None
) -> Path:
    """The checked MJCF file of ``uri``, a field of ``robot``'s manifest at ``field``,
    relative to ``manifest_dir`` (default: the folder the manifest was loaded from, else
    ``robots/<name>/``).

    Raises:
        ManifestError: At ``field``, saying why the URI does not give a usable file.
    """
    source = source_file(robot)
    folder = manifest_dir or (source.parent if source else manifest_path(robot.name).parent)
    try:
        return resolve_mjcf_uri(uri, folder)
    except MjcfUriError as error:
        raise error_at(robot, field, f"{error.uri!r}: {error.problem}") from None


def locate_mjcf_uri(uri: str, manifest_dir: Path | None = None) -> tuple[Path, Confinement | None]:
    """The file ``uri`` names and the root it must stay in, unchecked (None: no root known)."""
    scheme, sep, rest = uri.partition(":")
    if not sep or not rest:
        message = f"expected '<scheme>:<path>' with scheme one of {SCHEMES}"
        raise MjcfUriError(uri, message, manifest_dir)
    if scheme == "file":
        return _file_path(rest, uri, manifest_dir)
    if scheme == "pkg":
        distribution, inner = _package_parts(rest, uri, manifest_dir)
    elif scheme == "robosuite":
        _check_inner(rest, "'robosuite:<path inside models/assets>'", uri, manifest_dir)
        distribution, inner = "robosuite", f"robosuite/models/assets/{rest}"
    else:
        message = (
            f"unknown scheme {scheme!r}; expected one of {SCHEMES} (a file installed by a "
            f"Python distribution is {PKG_FORM})"
        )
        raise MjcfUriError(uri, message, manifest_dir)
    return distribution_file(distribution, inner, uri, manifest_dir)


DEPRECATED_SCHEMES = {"robosuite": "pkg:robosuite/robosuite/models/assets/"}
"""A deprecated scheme → the ``pkg:`` prefix that replaces it."""


def deprecated_uris(robot: RobotDescription) -> list[tuple[tuple[str, ...], str, str]]:
    """``(field, uri, replacement)`` of each model URI of ``robot`` in a deprecated scheme."""
    found: list[tuple[tuple[str, ...], str, str]] = []
    uris = [(("sim", "mjcf_uri"), robot.sim.mjcf_uri if robot.sim else None)]
    base = robot.mobile_base
    uris.append((("mobile_base", "mjcf_uri"), base.mjcf_uri if base else None))
    for field, uri in uris:
        scheme, _, rest = (uri or "").partition(":")
        if scheme in DEPRECATED_SCHEMES:
            found.append((field, str(uri), DEPRECATED_SCHEMES[scheme] + rest))
    return found


def _package_parts(rest: str, uri: str, manifest_dir: Path | None) -> tuple[str, str]:
    """``(distribution, path inside it)`` of a ``pkg:`` URI whose ``rest`` follows ``pkg:``."""
    distribution, slash, inner = rest.partition("/")
    if not slash or not inner:
        raise MjcfUriError(uri, f"expected {PKG_FORM}", manifest_dir)
    if not _DISTRIBUTION_NAME.fullmatch(distribution):
        message = (
            f"expected {PKG_FORM}, and {distribution!r} is not a distribution name "
            "(letters, digits, '.', '_' and '-', starting and ending with a letter or digit)"
        )
        raise MjcfUriError(uri, message, manifest_dir)
    _check_inner(inner, PKG_FORM, uri, manifest_dir)
    return distribution, inner


def _check_inner(inner: str, form: str, uri: str, manifest_dir: Path | None) -> None:
    """Refuse a path inside a distribution with an empty, ``.`` or ``..`` part."""
    if any(part in ("", ".", "..") for part in inner.split("/")):
        message = f"expected {form}, and the path {inner!r} has an empty, '.' or '..' part"
        raise MjcfUriError(uri, message, manifest_dir)


def distribution_file(
    distribution: str, inner: str, uri: str, manifest_dir: Path | None = None
) -> tuple[Path, Confinement]:
    """The installed file of ``distribution`` whose recorded path ends with ``inner``, and
    its confinement: the deepest folder holding every file of the distribution that sits
    in the same top-level folder as the model (``site-packages/<package>``, or
    ``share/<name>`` for data files)."""
    try:
        dist = metadata.distribution(distribution)
    except metadata.PackageNotFoundError:
        raise MjcfUriError(uri, _not_installed(distribution), manifest_dir) from None
    wanted = PurePosixPath(inner).parts
    records = [PurePosixPath(str(record)) for record in dist.files or ()]
    for record in records:
        if record.parts[-len(wanted) :] == wanted:
            path = Path(str(dist.locate_file(record))).resolve()
            root = _common_folder(record, records)
            label = f"the files of {distribution} {dist.version}"
            return path, Confinement.of(Path(str(dist.locate_file(root))), label)
    raise MjcfUriError(
        uri,
        f"{distribution} {dist.version} is installed but ships no file {inner!r}",
        manifest_dir,
    )


def _common_folder(model: PurePosixPath, records: list[PurePosixPath]) -> PurePosixPath:
    """Deepest folder holding every record that shares ``model``'s top-level folder."""
    ups = next((i for i, part in enumerate(model.parts) if part != ".."), len(model.parts) - 1)
    top = model.parts[: ups + 1]
    common = model.parent.parts
    for record in records:
        if record.parts[: ups + 1] == top:
            folder = record.parent.parts
            depth = next(
                (i for i, (a, b) in enumerate(zip(common, folder, strict=False)) if a != b), None
            )
            common = common[: min(len(common), len(folder)) if depth is None else depth]
    return PurePosixPath(*common)


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


def _file_path(rest: str, uri: str, manifest_dir: Path | None) -> tuple[Path, Confinement | None]:
    path = Path(rest)
    if manifest_dir is None:
        if not path.is_absolute():
            raise MjcfUriError(uri, "a relative file: path needs the manifest's folder")
        return Path(os.path.realpath(path)), None
    confinement = Confinement.of(manifest_dir, "the robot folder")
    return Path(os.path.realpath(manifest_dir / path)), confinement


def _normalise(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()
