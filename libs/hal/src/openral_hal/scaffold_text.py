"""How a drafted manifest writes values: YAML text that reads back as the same value, and
the ``# REVIEW:`` mark on guesses (shared by :mod:`openral_hal.scaffold` and
:mod:`openral_hal.scaffold_gains`)."""

from __future__ import annotations

import json
import re

DIGITS = 6
"""Decimals a drafted number keeps."""
REVIEW = "  # REVIEW:"
"""Marks a line whose value is a guess, a placeholder or a first estimate."""
_RESERVED = {"true", "false", "null", "yes", "no", "on", "off", "y", "n", "~"}
_PLAIN = re.compile(r"[A-Za-z][A-Za-z0-9_./:-]*(?: [A-Za-z0-9_./-]+)*")


def num(value: float, *, rounded: bool = True) -> str:
    """A float YAML reads back as a float: ``round(x, 6)`` in ``repr`` form, with a dot."""
    number = round(float(value), DIGITS) if rounded else float(value)
    if number == 0:
        number = 0.0  # no "-0.0"
    text = repr(number)
    mantissa, e, exponent = text.partition("e")
    if "." not in mantissa:
        mantissa += ".0"
    return f"{mantissa}{e}{exponent}"


def scalar(text: str) -> str:
    """``text`` as a YAML plain scalar where that reads back as the same string, else quoted."""
    plain = (
        _PLAIN.fullmatch(text) is not None
        and ": " not in text
        and not text.endswith(":")
        and text.lower() not in _RESERVED
    )
    return text if plain else json.dumps(text)
