"""Where `openral robot` commands find a robot's manifest."""

from __future__ import annotations

from pathlib import Path


def manifest_file(target: str) -> Path:
    """The manifest of ``target``: a robot folder, a manifest file, or a robot id."""
    from openral_core import manifest_path
    from openral_core.registry import MANIFEST_NAME

    path = Path(target)
    if path.is_dir():
        return path / MANIFEST_NAME
    if path.suffix in (".yaml", ".yml") or path.exists():
        return path
    return manifest_path(target)
