"""Keep an MJCF model, and every file it makes MuJoCo open, inside one folder.

A manifest's model is resolved to a file and a :class:`Confinement` (the robot's folder for
``file:``, the installed distribution's folder for the package schemes).
:func:`check_mjcf_files` then reads the model the way MuJoCo 3.x will, before MuJoCo opens
anything, and refuses any file reference that would leave that folder:

- ``<include file=...>``: relative to the main model's folder, or (MuJoCo's newer rule,
  tried when the first misses) to the including file's folder. Includes nest.
- ``file`` attributes (``file``, ``fileright``, ...) of ``mesh``, ``skin``, ``hfield``,
  ``flexcomp``: under ``<compiler meshdir>`` (else ``assetdir``); of ``texture``: under
  ``texturedir`` (else ``assetdir``); those folders are relative to the main model's
  folder unless absolute. Inside an included file MuJoCo may also look next to that file.
  ``strippath="true"`` keeps only the file name. Absolute file names are used as they are.
- ``<model file=...>`` sub-models: relative to the main model's folder, and checked in turn
  as models of their own.

Every place MuJoCo could pick is checked, both as the system resolves it (symlinks) and as
MuJoCo does (``..`` removed first); a backslash counts as a separator, as it does for
MuJoCo, and a name with ``<x>:/`` (a drive or resource provider to MuJoCo) is refused.
A ``file`` attribute on any other element is checked against every folder. The XML is
read with the standard library's expat (the parser under ElementTree, which resolves no
external entity) and a document type declaration is refused outright, so no entity can be
declared, expanded or fetched. Every problem is one :class:`MjcfConfinementError` line
naming the file, the line, the attribute and the offending path. With
``OPENRAL_ALLOW_OUTSIDE=1`` (:func:`outside_allowed`) callers skip the check.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import NoReturn
from xml.parsers import expat

from openral_core.errors import OpenralError

ALLOW_OUTSIDE_ENV = "OPENRAL_ALLOW_OUTSIDE"
"""Environment variable that, set to ``1``, lets a model and its files lie anywhere."""

MAX_XML_BYTES = 32 * 1024 * 1024
"""Largest MJCF file read (main model or include)."""

MAX_XML_FILES = 256
"""Most XML files (main model, includes, sub-models) one model may read."""

_MESH_TAGS = frozenset({"mesh", "skin", "hfield"})
_DIR_ATTRIBUTES = ("meshdir", "texturedir", "assetdir")


class MjcfConfinementError(OpenralError):
    """An MJCF file that names a file outside its confinement, or XML that is not safe to read."""


def outside_allowed(allow_outside: bool = False) -> bool:
    """True when this call (``allow_outside``) or the environment lets files leave their root."""
    return allow_outside or os.environ.get(ALLOW_OUTSIDE_ENV) == "1"


@dataclass(frozen=True)
class Confinement:
    """The folder a model and every file it loads must lie in.

    Attributes:
        root: Real path (symlinks resolved) of the folder.
        label: What the folder is, for messages (``the robot folder``, ``gym-aloha 0.1.5``).
    """

    root: Path
    label: str

    @classmethod
    def of(cls, folder: Path, label: str) -> Confinement:
        """The confinement of ``folder``, symlinks resolved."""
        return cls(Path(os.path.realpath(folder)), label)

    def contains(self, path: Path) -> bool:
        """True when ``path`` lies under the root (or is it), both as the system resolves
        it and as MuJoCo does (``..`` removed before symlinks are followed)."""
        root = str(self.root)
        inside = root.rstrip(os.sep) + os.sep
        for form in (str(path), os.path.normpath(path)):
            real = os.path.realpath(form)
            if real != root and not real.startswith(inside):
                return False
        return True

    def __str__(self) -> str:
        return f"{self.label} {self.root}"


@dataclass(frozen=True)
class _Ref:
    """One file attribute, where it was written and the folders MuJoCo may look in."""

    xml: Path
    line: int
    tag: str
    attribute: str
    value: str
    include_dir: Path | None
    """Folder of the included file the attribute sits in (None in the main model)."""


@dataclass
class _Model:
    """What one walk over a model (main file and includes) found."""

    main: Path
    dirs: dict[str, list[_Ref]] = field(default_factory=dict)
    refs: list[_Ref] = field(default_factory=list)
    submodels: list[_Ref] = field(default_factory=list)
    strippath: bool = False


class _Walk:
    """Reads a model and its includes in document order, checking includes before opening."""

    def __init__(self, confinement: Confinement, seen: set[str], files: list[Path]) -> None:
        self.confinement = confinement
        self.seen = seen
        self.files = files

    def model(self, main: Path) -> _Model:
        found = _Model(main)
        self._read(main, found, None)
        return found

    def _read(self, xml: Path, found: _Model, include_dir: Path | None) -> None:
        real = os.path.realpath(xml)
        if real in self.seen:
            return  # MuJoCo refuses a file included twice; nothing new to check
        self.seen.add(real)
        self.files.append(Path(real))
        if len(self.seen) > MAX_XML_FILES:
            raise MjcfConfinementError(
                f"{xml}: the model reads more than {MAX_XML_FILES} XML files; refusing it"
            )
        for line, tag, attributes in _elements(xml):
            self._element(xml, line, tag, attributes, found, include_dir)

    def _element(
        self,
        xml: Path,
        line: int,
        tag: str,
        attributes: dict[str, str],
        found: _Model,
        include_dir: Path | None,
    ) -> None:
        name = tag.lower()
        if name == "compiler":
            for key, value in attributes.items():
                if key.lower() in _DIR_ATTRIBUTES:
                    ref = _Ref(xml, line, tag, key, value, include_dir)
                    found.dirs.setdefault(key.lower(), []).append(ref)
                elif key.lower() == "strippath":
                    found.strippath = value.strip().lower() == "true"
        for key, value in attributes.items():
            if not key.lower().startswith("file"):
                continue
            ref = _Ref(xml, line, tag, key, value, include_dir)
            if name == "include" and key.lower() == "file":
                self._include(ref, found)
            elif name == "model":
                found.submodels.append(ref)
            else:
                found.refs.append(ref)

    def _include(self, ref: _Ref, found: _Model) -> None:
        here = ref.include_dir or found.main.parent
        places = _check_ref(ref, ref.value, [found.main.parent, here], self.confinement)
        self.files += places  # a file appearing at an earlier place would be read instead
        opened = next((place for place in places if place.is_file()), None)
        if opened is not None:  # else MuJoCo reports the missing file itself
            self._read(opened, found, opened.parent)


def check_mjcf_files(main: Path, confinement: Confinement) -> tuple[Path, ...]:
    """Refuse ``main`` when a file it makes MuJoCo open lies outside ``confinement``.

    Returns:
        Every XML file the model reads (real paths) and every place MuJoCo may look for a
        file it names, existing or not, each once.

    Raises:
        MjcfConfinementError: A reference leaves the confinement, or XML that cannot be read
            safely (not well-formed, a document type declaration, too large or too many files).
    """
    files: list[Path] = []
    _check_model(main, confinement, set(), files)
    return tuple(dict.fromkeys(files))


def mjcf_files(main: Path) -> tuple[Path, ...]:
    """What :func:`check_mjcf_files` returns, wherever the files lie (only unsafe XML, a
    drive or resource path and a non-regular file are refused)."""
    return check_mjcf_files(main, Confinement(Path(os.sep), "anywhere"))


def _check_model(main: Path, confinement: Confinement, seen: set[str], files: list[Path]) -> None:
    found = _Walk(confinement, seen, files).model(main)
    base = main.parent
    for refs in found.dirs.values():
        for ref in refs:
            _check_ref(ref, ref.value, [base], confinement, directory=True)
    mesh_dirs = _dir_values(found, "meshdir")
    texture_dirs = _dir_values(found, "texturedir")
    for ref in found.refs:
        tag = ref.tag.lower()
        if tag in _MESH_TAGS:
            dirs = mesh_dirs
        elif tag == "texture":
            dirs = texture_dirs
        else:  # flexcomp and any element MuJoCo may add: every folder it could use
            dirs = sorted({"", *mesh_dirs, *texture_dirs})
        value = _strip(ref.value) if found.strippath else ref.value
        folders = [_join(base, d) for d in dirs]
        if ref.include_dir is not None:
            folders.append(ref.include_dir)
        files += _check_ref(ref, value, folders, confinement)
    for ref in found.submodels:
        folders = [base] if ref.include_dir is None else [base, ref.include_dir]
        places = _check_ref(ref, ref.value, folders, confinement)
        opened = next((place for place in places if place.is_file()), None)
        if opened is not None:
            _check_model(opened, confinement, seen, files)


def _dir_values(found: _Model, attribute: str) -> list[str]:
    """Every value MuJoCo may use for ``attribute``: its own, else assetdir's, else ''."""
    own = [ref.value for ref in found.dirs.get(attribute, [])]
    shared = [ref.value for ref in found.dirs.get("assetdir", [])]
    return sorted(set(own + shared)) or [""]


def _join(base: Path, value: str) -> Path:
    path = Path(value.replace("\\", "/"))
    return path if path.is_absolute() else base / path


def _strip(value: str) -> str:
    """The file name MuJoCo keeps under ``strippath``: after the last slash or backslash."""
    return value.replace("\\", "/").rsplit("/", 1)[-1]


def _check_ref(
    ref: _Ref, value: str, folders: list[Path], confinement: Confinement, *, directory: bool = False
) -> list[Path]:
    """Every place MuJoCo may open for ``value``, refusing any outside the confinement, or
    (unless ``directory``) one that exists but is not a regular file (a FIFO would block).

    MuJoCo treats a backslash as a separator and ``<x>:/`` as an absolute path (a drive or
    a resource provider), so both spellings are checked and the latter is refused.
    """
    outside = f"outside {confinement}; set {ALLOW_OUTSIDE_ENV}=1 to allow files outside it"
    places: list[Path] = []
    for form in dict.fromkeys([value, value.replace("\\", "/")]):
        if ":/" in form:
            _refuse(ref, f"is read by MuJoCo as a drive or resource path, {outside}")
        if Path(form).is_absolute():
            places.append(Path(form))
        else:
            places += [folder / form for folder in folders]
    places = list(dict.fromkeys(places))
    for place in places:
        if not confinement.contains(place):
            _refuse(ref, f"resolves to {os.path.realpath(place)}, {outside}")
        if not directory and place.exists() and not place.is_file():
            _refuse(ref, f"resolves to {os.path.realpath(place)}, which is not a regular file")
    return places


def _refuse(ref: _Ref, problem: str) -> NoReturn:
    raise MjcfConfinementError(
        f"{ref.xml}:{ref.line}: <{ref.tag} {ref.attribute}={ref.value!r}> {problem}"
    )


def _elements(xml: Path) -> list[tuple[int, str, dict[str, str]]]:
    """(line, tag, attributes) of every element of ``xml``, in document order."""
    try:
        size = xml.stat().st_size
        if size > MAX_XML_BYTES:
            raise MjcfConfinementError(
                f"{xml}: {size} bytes is more than the {MAX_XML_BYTES} an MJCF file may have"
            )
        data = xml.read_bytes()
    except OSError as error:
        raise MjcfConfinementError(f"{xml}: cannot be read ({error.strerror})") from None
    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    elements: list[tuple[int, str, dict[str, str]]] = []

    def refuse_doctype(*_: object) -> None:
        raise MjcfConfinementError(
            f"{xml}:{parser.CurrentLineNumber}: a document type declaration (<!DOCTYPE>) is "
            "not allowed in an MJCF file; it could declare entities"
        )

    def start(tag: str, attributes: dict[str, str]) -> None:
        elements.append((parser.CurrentLineNumber, tag, attributes))

    parser.StartDoctypeDeclHandler = refuse_doctype
    parser.StartElementHandler = start
    try:
        parser.Parse(data, True)
    except expat.ExpatError as error:
        where = f"{xml}:{error.lineno}:{error.offset + 1}"
        raise MjcfConfinementError(
            f"{where}: not well-formed XML ({expat.ErrorString(error.code)})"
        ) from None
    return elements
