"""Options whose value may be left out: ``--ray`` alone means ``--ray local``.

click (under typer) has no option that takes a value only sometimes, so the command line is
completed before parsing: an option of :data:`OPTIONAL_VALUES` given last, or followed by
another option, gets its default value inserted.
"""

from __future__ import annotations

OPTIONAL_VALUES = {"--ray": "local"}
"""Option → the value it has when given alone."""


def with_optional_values(args: list[str]) -> list[str]:
    """``args`` with every value-less optional-value option completed."""
    completed: list[str] = []
    for index, arg in enumerate(args):
        completed.append(arg)
        following = args[index + 1] if index + 1 < len(args) else None
        if arg in OPTIONAL_VALUES and (following is None or following.startswith("-")):
            completed.append(OPTIONAL_VALUES[arg])
    return completed
