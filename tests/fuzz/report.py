"""What a campaign keeps: counts by outcome and stage, and one reproducer per finding.

A finding is a case whose outcome is in :data:`FINDINGS`; findings with the same outcome,
stage and signature are one entry, whose reproducer is the case with the lowest index (so
a campaign saves the same files whatever order its workers finish in). A reproducer is
the case's folder (the fuzzed file laid out as in :mod:`seeds`, and ``case.json``) plus
``detail.txt`` (message, traceback or stack dump) and ``result.json``.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rich.table import Table

from tests.fuzz.cases import CaseSpec
from tests.fuzz.outcome import FINDINGS, Outcome, Result
from tests.fuzz.seeds import seed_named

STAGES = ("load", "check", "hal", "scene")
"""Every stage, in the order a case meets them (manifests: load, check, hal; scenes: load,
scene)."""


@dataclass
class Finding:
    """One distinct finding: how often it happened and its saved reproducer."""

    outcome: Outcome
    stage: str
    signature: str
    count: int = 0
    index: int = -1
    reproducer: Path | None = None


@dataclass
class Report:
    """Counts and findings of a campaign, saving reproducers under ``out``."""

    out: Path
    campaign_seed: int
    counts: Counter[tuple[Outcome, str]] = field(default_factory=Counter)
    findings: dict[tuple[Outcome, str, str], Finding] = field(default_factory=dict)
    slowest: tuple[float, int] = (0.0, -1)
    """Seconds and index of the slowest case that finished (a killed one is a hang)."""

    def clear(self) -> None:
        """Remove the reproducers an earlier campaign saved under ``out``."""
        for outcome in FINDINGS:
            shutil.rmtree(self.out / outcome.value, ignore_errors=True)

    def add(self, index: int, spec: CaseSpec, folder: Path, result: Result) -> None:
        """Count case ``index``; save it as a reproducer when it is a finding's first."""
        self.counts[(result.outcome, result.stage)] += 1
        self.slowest = max(self.slowest, (result.seconds, index))
        if result.outcome not in FINDINGS:
            return
        key = (result.outcome, result.stage, result.signature)
        finding = self.findings.setdefault(key, Finding(*key))
        finding.count += 1
        if finding.index == -1 or index < finding.index:
            finding.index = index
            finding.reproducer = self._save(index, spec, folder, result)

    @property
    def failed(self) -> bool:
        """True when any case was a finding."""
        return bool(self.findings)

    def _save(self, index: int, spec: CaseSpec, folder: Path, result: Result) -> Path:
        key = f"{result.outcome}|{result.stage}|{result.signature}"
        target = self.out / result.outcome.value / hashlib.sha1(key.encode()).hexdigest()[:10]
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(folder, target)
        (target / "detail.txt").write_text(result.detail + "\n", encoding="utf-8")
        record: dict[str, Any] = {
            **result.to_json(),
            "campaign_seed": self.campaign_seed,
            "index": index,
            "case": spec.to_json(),
        }
        record.pop("detail")
        (target / "result.json").write_text(json.dumps(record, indent=2) + "\n", "utf-8")
        seed = seed_named(spec.seed)
        relative = f"{seed.robot}/robot.yaml" if seed.kind == "manifest" else seed.path.name
        return target / relative

    def outcome_table(self) -> Table:
        """Counts by outcome (rows) and stage (columns)."""
        table = Table(title="fuzz cases by outcome and stage")
        table.add_column("outcome")
        for stage in STAGES:
            table.add_column(stage, justify="right")
        table.add_column("total", justify="right")
        for outcome in Outcome:
            cells = [self.counts[(outcome, stage)] for stage in STAGES]
            table.add_row(outcome.value, *map(str, cells), str(sum(cells)))
        totals = [sum(n for (_, s), n in self.counts.items() if s == st) for st in STAGES]
        table.add_row("all", *map(str, totals), str(sum(totals)), style="bold")
        return table

    def findings_text(self) -> str:
        """Every distinct finding: outcome, stage, count, signature, reproducer, replay."""
        blocks: list[str] = []
        ordered = sorted(self.findings.values(), key=lambda f: (f.outcome, f.stage, -f.count))
        for finding in ordered:
            where = _shown(finding.reproducer)
            folder = _shown(_case_folder(finding.reproducer))
            blocks.append(
                f"{finding.outcome.value} in {finding.stage}, {finding.count}x: "
                f"{finding.signature}\n"
                f"  reproducer: {where}\n"
                f"  replay:     python -m tests.fuzz.replay {folder}"
            )
        return "\n".join(blocks)

    def write_summary(self) -> Path:
        """Write ``summary.json`` (counts and findings) under ``out``; return its path."""
        summary = {
            "campaign_seed": self.campaign_seed,
            "slowest_case": {"seconds": self.slowest[0], "index": self.slowest[1]},
            "counts": [
                {"outcome": o.value, "stage": s, "count": n} for (o, s), n in self.counts.items()
            ],
            "findings": [
                {
                    "outcome": f.outcome.value,
                    "stage": f.stage,
                    "signature": f.signature,
                    "count": f.count,
                    "index": f.index,
                    "reproducer": str(f.reproducer),
                }
                for f in self.findings.values()
            ],
        }
        path = self.out / "summary.json"
        path.write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
        return path


def _case_folder(reproducer: Path | None) -> Path | None:
    """The reproducer's folder (the one holding ``case.json``)."""
    if reproducer is None:
        return None
    return next((p for p in reproducer.parents if (p / "case.json").is_file()), reproducer)


def _shown(path: Path | None) -> str:
    """``path`` relative to the working folder when it is inside it."""
    if path is None:
        return "-"
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)
