"""A fuzz case: a seed and its mutations, drawn from a campaign seed and written to disk.

Case ``i`` of campaign seed ``s`` depends on ``(s, i)`` alone, so a campaign gives the same
cases whatever the number of workers or the order they finish in.
"""

from __future__ import annotations

import json
import random
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from tests.fuzz.mutators import Mutation, apply_mutations, draw_mutations
from tests.fuzz.seeds import donors, lay_out, seed_named, seeds
from tests.fuzz.stages import Case


@dataclass(frozen=True)
class CaseSpec:
    """Which seed to start from and which mutations to apply, in order."""

    seed: str
    mutations: tuple[Mutation, ...]

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (saved next to a reproducer as ``case.json``)."""
        return {"seed": self.seed, "mutations": [list(m) for m in self.mutations]}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> CaseSpec:
        """The inverse of :meth:`to_json`."""
        return cls(str(data["seed"]), tuple((str(n), int(s)) for n, s in data["mutations"]))


def draw_case(campaign_seed: int, index: int) -> CaseSpec:
    """Case ``index`` of the campaign seeded ``campaign_seed``."""
    rng = random.Random(f"{campaign_seed}:{index}")
    pool = seeds()
    seed = rng.choices(pool, weights=[s.weight for s in pool])[0]
    return CaseSpec(seed.name, draw_mutations(rng))


@cache
def _donors() -> tuple[bytes, ...]:
    return donors()


def case_bytes(spec: CaseSpec) -> bytes:
    """The mutated file of ``spec``."""
    return apply_mutations(seed_named(spec.seed).read(), spec.mutations, _donors())


def write_case(spec: CaseSpec, folder: Path, *, load_only_slow: bool = False) -> Case:
    """Write the mutated file of ``spec`` under ``folder`` (see :func:`seeds.lay_out`).

    Args:
        spec: The case.
        folder: An empty folder for it.
        load_only_slow: Run a slow (robosuite) seed through ``load`` only.
    """
    seed = seed_named(spec.seed)
    file = lay_out(seed, case_bytes(spec), folder)
    (folder / "case.json").write_text(json.dumps(spec.to_json()) + "\n", encoding="utf-8")
    return Case(file, seed.kind, seed.robot, load_only=load_only_slow and seed.slow)
