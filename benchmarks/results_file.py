"""Where and how a benchmark writes its JSON result (with the machine it ran on)."""

from __future__ import annotations

import json
import platform
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

RESULTS_DIR = Path(__file__).parent / "results"


def write_results(name: str, payload: dict[str, Any]) -> Path:
    """Write ``payload`` plus machine facts to ``benchmarks/results/<name>.json``."""
    RESULTS_DIR.mkdir(parents=True, exist_ok=True)
    path = RESULTS_DIR / f"{name}.json"
    report = {
        "machine": platform.machine(),
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "numpy": np.__version__,
        **payload,
    }
    path.write_text(json.dumps(report, indent=2) + "\n")
    return path
