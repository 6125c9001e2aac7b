"""The docs site builds strictly and its reference covers every schema property."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from openral_codegen.schema_docs import property_names, read_schemas
from openral_core.schemas import SchemaName

from tests.conftest import REPO


def test_mkdocs_build_strict(tmp_path: Path) -> None:
    mkdocs = Path(sys.executable).with_name("mkdocs")
    result = subprocess.run(
        [str(mkdocs), "build", "--strict", "--site-dir", str(tmp_path / "site")],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=False,
        env={"NO_MKDOCS_2_WARNING": "1", "PATH": str(mkdocs.parent)},
    )
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "site" / "reference" / "robot" / "index.html").is_file()


def test_reference_pages_list_every_schema_property() -> None:
    schemas = read_schemas(REPO / "schema")
    for name in SchemaName:
        page = (REPO / "docs" / "reference" / f"{name.value}.md").read_text()
        missing = [p for p in sorted(property_names(schemas[name])) if f"| `{p}` |" not in page]
        assert not missing, f"docs/reference/{name.value}.md lacks {missing}"
