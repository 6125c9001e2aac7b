"""Count how often each YAML file is parsed: every manifest and scene load of the project goes
through ``openral_core.loader.load_located``, so wrapping it there counts them all."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest
from openral_core import loader
from openral_core.yaml_source import LocatedDocument


def count_parses(monkeypatch: pytest.MonkeyPatch) -> Counter[Path]:
    """Start counting parses by resolved file path (until the test ends)."""
    counts: Counter[Path] = Counter()
    parse = loader.load_located

    def counting(file: Path) -> LocatedDocument:
        counts[Path(file).resolve()] += 1
        return parse(file)

    monkeypatch.setattr(loader, "load_located", counting)
    return counts


def stale_franka_table(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Make franka_panda's generated tables stale: a copy whose manifest hash is wrong,
    in a generated folder the loader is pointed at."""
    from openral_core import loaded
    from openral_core.paths import generated_dir

    table = Path("openral_generated", "tables", "franka_panda.json")
    text = (generated_dir() / table).read_text()
    assert text.count('"manifest_sha256": "') == 1
    copy = tmp_path / "generated" / table
    copy.parent.mkdir(parents=True)
    copy.write_text(text.replace('"manifest_sha256": "', '"manifest_sha256": "0', 1))
    monkeypatch.setattr(loaded, "generated_dir", lambda: tmp_path / "generated")
