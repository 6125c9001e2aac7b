"""A campaign's worker process: runs the cases it is sent, one JSON line at a time.

Started as ``python -m tests.fuzz.worker --log FILE``. It reads one case per line on stdin
(``{"file", "kind", "robot", "load_only"}``) and answers on its stdout with
``{"stage": name}`` as each stage starts and ``{"result": {...}}`` at the end. Everything
the libraries print goes to /dev/null, so only the protocol uses that pipe. Its address
space is capped at :data:`ADDRESS_SPACE_LIMIT` (the campaign also kills a worker whose
resident memory passes 4 GiB); :mod:`faulthandler` writes the stack to the log file on a
fatal signal and when a case passes :data:`HANG_SECONDS`, for the campaign to read.
"""

from __future__ import annotations

import argparse
import faulthandler
import importlib
import json
import os
import resource
import sys
from contextlib import suppress
from pathlib import Path
from typing import IO, Any

from tests.fuzz.outcome import HANG_SECONDS
from tests.fuzz.seeds import seed_named
from tests.fuzz.stages import Case, run_case

ADDRESS_SPACE_LIMIT = 8 << 30
"""Address-space cap of a worker [bytes]. Resident memory is what the campaign bounds (to
4 GiB); address space runs far ahead of it: a robosuite scene maps about 5 GiB while using
1 GiB."""
WARM_UP = ("rizon4/robot.yaml", "rizon4/scenes/tabletop.yaml")
"""Seeds run once before the first case, so imports and the first GL context are not
charged to it."""


def _protocol_pipe() -> IO[str]:
    """A private copy of stdout for the protocol; fd 1 and 2 then go to /dev/null."""
    pipe = os.fdopen(os.dup(1), "w", buffering=1, encoding="utf-8")
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    os.dup2(null, 2)
    return pipe


def _send(pipe: IO[str], message: dict[str, Any]) -> None:
    pipe.write(json.dumps(message) + "\n")
    pipe.flush()


def _warm_up() -> None:
    """Import what cases use and run the warm-up seeds."""
    for module in ("openral_cli.commands.robot", "openral_hal.factory", "openral_sim.native_scene"):
        importlib.import_module(module)
    with suppress(ImportError):
        importlib.import_module("openral_sim.robosuite_backend")
    for name in WARM_UP:
        seed = seed_named(name)
        run_case(Case(seed.path, seed.kind, seed.robot))


def main() -> None:
    """Serve cases until stdin closes."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--log", type=Path, required=True, help="faulthandler output file")
    args = parser.parse_args()
    os.environ.setdefault("MUJOCO_GL", "egl")
    resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_SPACE_LIMIT, ADDRESS_SPACE_LIMIT))
    pipe = _protocol_pipe()
    log = args.log.open("w", encoding="utf-8")
    faulthandler.enable(file=log, all_threads=True)
    _warm_up()
    _send(pipe, {"ready": True})
    for line in sys.stdin:
        request = json.loads(line)
        case = Case(Path(request["file"]), request["kind"], request["robot"], request["load_only"])
        log.seek(0)
        log.truncate()
        faulthandler.dump_traceback_later(HANG_SECONDS, file=log)
        result = run_case(case, lambda stage: _send(pipe, {"stage": stage}))
        faulthandler.cancel_dump_traceback_later()
        _send(pipe, {"result": result.to_json()})


if __name__ == "__main__":
    main()
