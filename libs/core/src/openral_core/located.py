"""Errors found after loading, located at the field they concern.

The loader remembers each document's positions on the model it builds. A stage that runs
later (scene build, HAL connect, ``robot check``) and finds a field at fault raises
:func:`error_at` with the model and the field's path, so the user reads the same
``file:line:col: field: message`` line the loader would have printed.

Example::

    raise error_at(scene, ("scene", "options", "objects", 1, "name"), "duplicate name")
"""

from __future__ import annotations

from pathlib import Path

from openral_base import OpenralModel

from openral_core.errors import Issue, ManifestError, PathKey, format_field
from openral_core.yaml_source import LocatedDocument


def remember_source(model: OpenralModel, document: LocatedDocument) -> None:
    """Record that ``model`` was built from ``document`` (the loader calls this)."""
    model._source = document


def source_of(model: OpenralModel) -> LocatedDocument | None:
    """The document ``model`` was loaded from, or None for a model built in code."""
    source = model._source
    return source if isinstance(source, LocatedDocument) else None


def source_file(model: OpenralModel) -> Path | None:
    """The file ``model`` was loaded from, or None for a model built in code."""
    document = source_of(model)
    return document.file if document is not None else None


def issue_at(model: OpenralModel, path: PathKey, message: str) -> Issue:
    """An :class:`Issue` at ``path`` of the file ``model`` came from.

    A model built in code has no file: the issue names its class and has position 0:0.
    """
    document = source_of(model)
    if document is None:
        unsaved = Path(f"<{type(model).__name__} not loaded from a file>")
        return Issue(unsaved, 0, 0, format_field(path), message)
    return document.issue(path, message)


def error_at(model: OpenralModel, path: PathKey, message: str) -> ManifestError:
    """A :class:`ManifestError` with one issue at ``path`` of the file ``model`` came from."""
    issue = issue_at(model, path, message)
    return ManifestError(issue.file, [issue])
