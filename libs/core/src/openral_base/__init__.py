"""Base class of every generated contract model (datamodel-codegen ``--base-class``).

It lives in its own tiny package because ``openral_core`` imports the generated models:
a base class inside ``openral_core`` would make importing the models first circular.

No field of the contract admits ``null``: an optional field is left out, never set to
null. JSON Schema says so by typing each field without ``null``; this base class says the
same for the models, whose optional fields are typed ``X | None`` so that "absent" can
be represented.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, PrivateAttr, model_validator

__all__ = ["OpenralModel"]


class OpenralModel(BaseModel):
    """Strict contract model: unknown fields and explicit nulls are rejected."""

    model_config = ConfigDict(extra="forbid")

    _source: object | None = PrivateAttr(default=None)
    """Where a document loaded from a file came from (set by ``openral_core``'s loader;
    read through ``openral_core.located``), so later stages can point into the file."""

    @model_validator(mode="before")
    @classmethod
    def _reject_explicit_null(cls, data: Any) -> Any:
        if isinstance(data, dict):
            nulls = sorted(str(key) for key, value in data.items() if value is None)
            if nulls:
                raise ValueError(
                    f"null is not allowed for {', '.join(nulls)}; leave the field out instead"
                )
        return data
