"""Run one fuzz case again, in this process, and print how it ends.

Usage::

    python -m tests.fuzz.replay fuzz-findings/traceback/<id>/      # a saved reproducer
    python -m tests.fuzz.replay fuzz-findings/traceback/<id>/g1/robot.yaml
    python -m tests.fuzz.replay --case 0:1234                      # campaign seed 0, case 1234
    python -m tests.fuzz.replay --spec '{"seed": "g1/robot.yaml", "mutations": [...]}'

A saved reproducer runs from its saved bytes (not regenerated), so it keeps failing the
same way even after the mutators change. Exit code 1 when the case is a finding.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

from tests.fuzz.cases import CaseSpec, draw_case, write_case
from tests.fuzz.outcome import FINDINGS, HANG_SECONDS, Result
from tests.fuzz.seeds import seed_named
from tests.fuzz.stages import Case, run_case, time_limit


def saved_case(path: Path) -> Case:
    """The case saved at ``path``: a reproducer folder or the fuzzed file inside it.

    Raises:
        FileNotFoundError: No ``case.json`` in the folder or above the file.
    """
    folder = (
        path
        if path.is_dir()
        else next((p for p in path.parents if (p / "case.json").is_file()), path.parent)
    )
    spec = CaseSpec.from_json(json.loads((folder / "case.json").read_text(encoding="utf-8")))
    seed = seed_named(spec.seed)
    if seed.kind == "manifest":
        file = folder / seed.robot / "robot.yaml"
    else:
        file = folder / seed.path.name
    return Case(file.resolve(), seed.kind, seed.robot)


def replay(case: Case) -> Result:
    """Run ``case`` with the hang time limit and print its outcome and detail."""
    with time_limit(HANG_SECONDS * 3):
        result = run_case(case)
    print(f"file: {case.file} ({case.kind} for {case.robot})")
    print(f"outcome: {result.outcome} in stage {result.stage} ({result.seconds:.2f} s)")
    if result.signature:
        print(f"signature: {result.signature}")
    if result.detail:
        print(result.detail)
    return result


def main(argv: list[str] | None = None) -> int:
    """Replay from the command line; exit code 1 on a finding."""
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz.replay", description=__doc__)
    parser.add_argument("path", nargs="?", type=Path, help="reproducer folder or fuzzed file")
    parser.add_argument("--case", help="SEED:INDEX of a campaign's case")
    parser.add_argument("--spec", help="a case as JSON (what the pytest test prints)")
    args = parser.parse_args(argv)
    os.environ.setdefault("MUJOCO_GL", "egl")
    if args.path is not None:
        result = replay(saved_case(args.path))
    elif args.case or args.spec:
        if args.case:
            seed, _, index = args.case.partition(":")
            spec = draw_case(int(seed), int(index))
        else:
            spec = CaseSpec.from_json(json.loads(args.spec))
        folder = Path(tempfile.mkdtemp(prefix="openral-replay-"))
        print(f"case {json.dumps(spec.to_json())} written under {folder}")
        result = replay(write_case(spec, folder))
    else:
        parser.error("name a reproducer, --case SEED:INDEX or --spec JSON")
    return 1 if result.outcome in FINDINGS else 0


if __name__ == "__main__":
    sys.exit(main())
