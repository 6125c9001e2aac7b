"""A disk cache of compiled MuJoCo models, so a model whose inputs have not changed loads in
milliseconds instead of being compiled again.

Compiling decodes every mesh file a model names (about 0.6 s for the Panda's 33 MB of STL on
one core, the largest part of ``openral deploy sim``'s start-up); loading the compiled
binary (MJB, :func:`mujoco.mj_saveModel`) takes about 35 ms. An entry is found by a key,
the SHA-256 of:

- this cache's format and the ``mujoco`` version;
- the caller's description of what it compiles (e.g. a scene file and a manifest as JSON,
  and :func:`code_digest` of the code that composes them);
- :func:`files_fingerprint` of every file the MJCF makes MuJoCo read and every place it may
  look for one (path, size, modification time, or "missing"), as
  :func:`~openral_mujoco.mjcf_confinement.mjcf_files` lists them.

So editing a mesh, an include, a manifest, a scene or the composing code, or installing
another MuJoCo, compiles afresh. Errors are never cached (a model that fails to compile
fails every time), an unreadable or damaged entry is compiled again and replaced, and a
folder that cannot be written only costs the time saved. Entries are written whole (a
temporary file renamed into place), so processes can share the folder; the least recently
used are removed once the folder holds more than :data:`MAX_BYTES`.

A process also keeps the entries it loaded most recently in memory (at most
:data:`MEMORY_BYTES` of them) and hands out copies: copying a model is about 4x faster than
reading its entry again (42 ms against 168 ms for a 36 MB model), which counts where one
process connects a HAL many times (a sweep's resets, a test's examples).

The folder is ``$OPENRAL_MODEL_CACHE`` when set (``off`` turns the cache off), else
``$XDG_CACHE_HOME/openral/models``, else ``~/.cache/openral/models``.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import os
import tempfile
from collections import OrderedDict
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from types import ModuleType

import mujoco

from openral_mujoco.mjcf_confinement import MjcfConfinementError, mjcf_files

CACHE_ENV = "OPENRAL_MODEL_CACHE"
"""Environment variable naming the cache folder, or ``off`` for no cache."""

FORMAT = "openral-mjb-1"
"""Changes whenever what an entry holds changes, so old entries are never read."""

MAX_BYTES = 1 << 30
"""The folder is pruned, least recently used first, to this many bytes [B]."""

MEMORY_BYTES = 256 << 20
"""At most this many bytes of entries [B] (their MJB sizes) stay in a process's memory."""

SUFFIX = ".mjb"

_MEMORY: OrderedDict[str, tuple[mujoco.MjModel, tuple[int, int]]] = OrderedDict()
"""Entries loaded in this process, least recently used first: (model, (the entry's size
[B], its inode) when it was read), so an entry replaced or damaged since is read again
(not its modification time: every process that reads an entry touches it)."""


def cache_folder() -> Path | None:
    """The cache folder (not created here), or None when the cache is off."""
    chosen = os.environ.get(CACHE_ENV, "").strip()
    if chosen.lower() in {"off", "0", "false", "no"}:
        return None
    if chosen:
        return Path(chosen).expanduser()
    base = os.environ.get("XDG_CACHE_HOME", "").strip() or str(Path.home() / ".cache")
    return Path(base) / "openral" / "models"


def files_fingerprint(paths: Iterable[Path]) -> str:
    """Digest of each path with its size and modification time [ns], or "missing"."""
    digest = hashlib.sha256()
    for path in paths:
        try:
            info = path.stat()
            state = f"{info.st_size}:{info.st_mtime_ns}"
        except OSError:
            state = "missing"
        digest.update(f"{path}\0{state}\n".encode())
    return digest.hexdigest()


def code_digest(*packages: ModuleType) -> str:
    """Digest of the Python source of ``packages`` (every ``*.py`` beside their
    ``__init__``), so entries built by other code are never read."""
    digest = hashlib.sha256()
    for package in packages:
        folder = Path(package.__file__ or "").parent
        for source in sorted(folder.glob("*.py")):
            digest.update(source.name.encode() + b"\0" + source.read_bytes())
    return digest.hexdigest()


def cache_key(parts: Sequence[str]) -> str:
    """The entry name of ``parts`` under this format and this MuJoCo."""
    digest = hashlib.sha256(f"{FORMAT}\0{mujoco.__version__}".encode())
    for part in parts:
        digest.update(b"\0" + part.encode())
    return digest.hexdigest()


def mjcf_fingerprint(path: Path) -> str | None:
    """:func:`files_fingerprint` of what the MJCF at ``path`` reads; None when its files
    cannot be listed (XML the walk refuses: then nothing is cached and MuJoCo reports)."""
    try:
        return files_fingerprint(mjcf_files(path))
    except MjcfConfinementError:
        return None


def cached_mjcf(
    path: Path,
    kind: str,
    refused: Callable[[ValueError], Exception],
    edit: Callable[[mujoco.MjSpec], object] | None = None,
) -> tuple[mujoco.MjModel, str | None]:
    """The model of the MJCF file at ``path``, compiled or read from the cache under
    ``kind`` (what the file is: ``robot``, ``base``), and its :func:`mjcf_fingerprint`
    (None: not cached). MuJoCo's refusal (a ValueError) is raised as ``refused(error)``.
    ``edit`` changes the file's spec before it is compiled (``kind`` must then name the
    edit, so an entry compiled without it is never read)."""

    def build() -> mujoco.MjModel:
        try:
            if edit is None:
                return mujoco.MjModel.from_xml_path(str(path))
            spec = mujoco.MjSpec.from_file(str(path))
            edit(spec)
            return spec.compile()
        except ValueError as error:  # MuJoCo's parser and compiler report this way
            raise refused(error) from None

    fingerprint = mjcf_fingerprint(path)
    parts = None if fingerprint is None else (kind, fingerprint)
    return cached_model(parts, build), fingerprint


def cached_model(
    parts: Sequence[str] | None, build: Callable[[], mujoco.MjModel]
) -> mujoco.MjModel:
    """The model ``build`` compiles for ``parts`` (see the module doc), from the cache when
    an entry exists (None: not cached); ``build``'s errors propagate and are not cached."""
    folder = cache_folder()
    if folder is None or parts is None:
        return build()
    entry = folder / (cache_key(parts) + SUFFIX)
    kept = _MEMORY.get(entry.name)
    if kept is not None and kept[1] == _stamp(entry):
        _MEMORY.move_to_end(entry.name)
        return copy.copy(kept[0])  # the caller may edit its model (gravity, say)
    model = _load(entry)
    if model is None:
        model = build()
        _store(model, entry)
    _remember(entry, model)
    return model


def _stamp(entry: Path) -> tuple[int, int] | None:
    """The entry's (size [B], inode); None when it is not there."""
    try:
        info = entry.stat()
    except OSError:
        return None
    return info.st_size, info.st_ino


def _remember(entry: Path, model: mujoco.MjModel) -> None:
    """Keep a copy of ``entry``'s model in memory, forgetting the least recently used
    beyond :data:`MEMORY_BYTES`; an entry that could not be written is not kept."""
    stamp = _stamp(entry)
    if stamp is None:
        return
    _MEMORY[entry.name] = (copy.copy(model), stamp)
    _MEMORY.move_to_end(entry.name)
    while sum(size for _, (size, _) in _MEMORY.values()) > MEMORY_BYTES and len(_MEMORY) > 1:
        _MEMORY.popitem(last=False)


def _load(entry: Path) -> mujoco.MjModel | None:
    """The entry's model, marked as just used; None when absent or unreadable (then it is
    removed, to be written again)."""
    if not entry.is_file():
        return None
    try:
        model = mujoco.MjModel.from_binary_path(str(entry))
    except Exception:  # damaged or foreign: compile instead
        entry.unlink(missing_ok=True)
        return None
    with contextlib.suppress(OSError):
        os.utime(entry)
    return model


def _store(model: mujoco.MjModel, entry: Path) -> None:
    """Write ``model`` to ``entry`` whole, then prune; an unwritable folder is not an error."""
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=entry.parent, suffix=".part")
        os.close(handle)
        try:
            mujoco.mj_saveModel(model, temporary, None)
            Path(temporary).replace(entry)
        finally:
            Path(temporary).unlink(missing_ok=True)
        prune(entry.parent, MAX_BYTES, keep=entry)
    except OSError:
        return


def prune(folder: Path, max_bytes: int, keep: Path | None = None) -> list[Path]:
    """Remove the least recently used entries until ``folder`` holds at most ``max_bytes``
    of them (``keep`` stays); returns what was removed."""
    entries = []
    for path in folder.glob("*" + SUFFIX):
        try:
            info = path.stat()
        except OSError:
            continue
        entries.append((info.st_mtime_ns, info.st_size, path))
    total = sum(size for _, size, _ in entries)
    removed = []
    for _, size, path in sorted(entries):
        if total <= max_bytes:
            break
        if path == keep:
            continue
        path.unlink(missing_ok=True)
        total -= size
        removed.append(path)
    return removed
