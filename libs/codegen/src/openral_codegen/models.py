"""Generate the pydantic models from schema/ with datamodel-code-generator.

Every flag lives in ``[tool.datamodel-codegen]`` of the root ``pyproject.toml``; this
module only chooses the output folder, so the generator's output is a pure function of
the schema files and the pinned generator and ruff versions.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

# Nothing from openral_core is imported here: the models must be writable even when the
# committed ones are stale or broken (openral_core imports them).


class CodegenError(RuntimeError):
    """The generator could not run (a tool is missing or failed)."""


def generate_models(repo_root: Path, out_dir: Path) -> None:
    """Write the models package for every ``schema/*.schema.json`` into ``out_dir``."""
    tool = Path(sys.executable).with_name("datamodel-codegen")
    if not tool.exists():
        raise CodegenError(f"{tool} not found; run `./bootstrap schema-export` to install it")
    env = {**os.environ, "RUFF_NO_CACHE": "true"}
    result = subprocess.run(
        [str(tool), "--input", "schema", "--output", str(out_dir)],
        cwd=repo_root,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if result.returncode != 0:
        raise CodegenError(f"datamodel-codegen failed:\n{result.stderr.strip()}")
    (out_dir / "__init__.py").write_text(
        "# GENERATED from schema/ by `just schema-export` -- do not edit.\n"
        '"""Pydantic models of the contract, one module per schema file."""\n',
        encoding="utf-8",
    )
