"""Quiet robosuite's import: the notices it logs about optional parts openral never uses."""

from __future__ import annotations

import logging


class _ImportNotices(logging.Filter):
    """Drops the notices robosuite logs about optional parts openral never uses (a private
    macros file, robosuite_models, mink's whole-body IK) and about loading its default
    controller file; everything else robosuite logs still shows."""

    NOTICES = (
        "private macro file",
        "setup_macros.py",
        "robosuite_models",
        "mink-based",
        "Loading controller configuration from",
    )

    def filter(self, record: logging.LogRecord) -> bool:
        return not any(notice in record.getMessage() for notice in self.NOTICES)


def quiet_robosuite_notices() -> None:
    """Filter the notices out of robosuite's logger (idempotent)."""
    logger = logging.getLogger("robosuite_logs")
    if not any(isinstance(f, _ImportNotices) for f in logger.filters):
        logger.addFilter(_ImportNotices())
