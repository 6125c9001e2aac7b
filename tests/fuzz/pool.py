"""Worker processes that run cases with a time limit, and replace themselves when one dies.

:func:`run_pool` hands each case to an idle worker (``python -m tests.fuzz.worker``) and
yields every case's :class:`Result`. A case still running :data:`KILL_AFTER` seconds after
it was sent is a ``hang``: its worker is killed (the stack faulthandler wrote at
:data:`HANG_SECONDS` is the detail) and replaced. A worker that dies mid-case yields a
``crash`` and is replaced, and so is one whose resident memory passes :data:`RSS_LIMIT`.
No case can end the campaign.
"""

from __future__ import annotations

import json
import os
import selectors
import signal
import subprocess
import sys
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from tests.fuzz.outcome import HANG_SECONDS, Result, crash, hang
from tests.fuzz.stages import Case

KILL_AFTER = HANG_SECONDS + 5.0
"""Seconds after which a worker still on a case is killed (faulthandler dumps at 10 s)."""
START_TIMEOUT = 180.0
"""Seconds a new worker may take to import and warm up."""
RSS_LIMIT = 4 << 30
"""Resident memory [bytes] past which a worker is killed and its case is a ``crash``."""
CASES_PER_WORKER = 400
"""A worker is replaced after this many cases, so leaks cannot pile up."""


class PoolError(RuntimeError):
    """A worker could not even start: the environment, not a case, is broken."""


@dataclass
class _Worker:
    """One worker process and the case it is running."""

    number: int
    folder: Path
    process: subprocess.Popen[bytes] = field(init=False)
    buffer: bytes = b""
    ticket: Any = None
    stage: str = "load"
    sent_at: float = 0.0
    served: int = 0

    def __post_init__(self) -> None:
        self.start()

    @property
    def log(self) -> Path:
        return self.folder / f"worker-{self.number}.log"

    def start(self) -> None:
        """Start the process and wait until it has warmed up."""
        command = [sys.executable, "-m", "tests.fuzz.worker", "--log", str(self.log)]
        env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
        env["OPENRAL_MODEL_CACHE"] = "off"  # every case is new: caching would only write
        self.process = subprocess.Popen(
            command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env, cwd=Path.cwd()
        )
        self.buffer, self.ticket, self.served = b"", None, 0
        os.set_blocking(self._out.fileno(), False)
        deadline = time.monotonic() + START_TIMEOUT
        while time.monotonic() < deadline:
            for message in self.read(timeout=1.0):
                if message.get("ready"):
                    return
            if self.process.poll() is not None:
                break
        self.stop()
        raise PoolError(f"worker {self.number} did not start; see {self.log}")

    @property
    def _out(self) -> Any:
        assert self.process.stdout is not None
        return self.process.stdout

    def read(self, timeout: float = 0.0) -> list[dict[str, Any]]:
        """The complete messages available now (waiting up to ``timeout`` for the first)."""
        with selectors.DefaultSelector() as selector:
            selector.register(self._out, selectors.EVENT_READ)
            if timeout and not selector.select(timeout):
                return []
        try:
            chunk = os.read(self._out.fileno(), 1 << 16)
        except BlockingIOError:
            chunk = b""
        self.buffer += chunk
        *lines, self.buffer = self.buffer.split(b"\n")
        return [json.loads(line) for line in lines if line.strip()]

    def send(self, ticket: Any, case: Case) -> None:
        """Start ``case``; ``ticket`` comes back with its result."""
        assert self.process.stdin is not None
        request: dict[str, Any] = {"file": str(case.file), "kind": case.kind}
        request.update(robot=case.robot, load_only=case.load_only)
        self.process.stdin.write((json.dumps(request) + "\n").encode())
        self.process.stdin.flush()
        self.ticket, self.stage, self.sent_at = ticket, "load", time.monotonic()
        self.served += 1

    def dump(self) -> str:
        """What faulthandler wrote for the current case."""
        try:
            return self.log.read_text(encoding="utf-8", errors="replace")
        except OSError:
            return ""

    def resident_bytes(self) -> int:
        """The process's resident memory (0 when it cannot be read)."""
        try:
            status = Path(f"/proc/{self.process.pid}/status").read_text(encoding="utf-8")
        except OSError:
            return 0
        kib = next((ln.split()[1] for ln in status.splitlines() if ln.startswith("VmRSS:")), "0")
        return int(kib) * 1024

    def stop(self) -> None:
        """Kill the process (if alive) and reap it."""
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        for stream in (self.process.stdin, self.process.stdout):
            if stream is not None:
                stream.close()


def _poll(worker: _Worker) -> Result | None:
    """The result of ``worker``'s case if it ended (finished, overran or died)."""
    try:
        messages = worker.read()
    except (OSError, ValueError):
        messages = []
    for message in messages:
        if "stage" in message:
            worker.stage = message["stage"]
        elif "result" in message:
            return Result.from_json(message["result"])
    if worker.process.poll() is not None:
        time.sleep(0.2)  # let faulthandler's dump reach the file
        code = worker.process.returncode
        cause = f"killed by {signal.Signals(-code).name}" if code < 0 else f"exit code {code}"
        return crash(worker.stage, worker.dump(), cause)
    resident = worker.resident_bytes()
    if resident > RSS_LIMIT:
        worker.stop()
        what = f"resident memory {resident / 2**30:.1f} GiB > {RSS_LIMIT / 2**30:g} GiB"
        return crash(worker.stage, "", what)
    elapsed = time.monotonic() - worker.sent_at
    if elapsed > KILL_AFTER:
        worker.stop()
        return hang(worker.stage, worker.dump(), elapsed)
    return None


def run_pool(
    jobs: Iterable[tuple[Any, Case]], count: int, folder: Path
) -> Iterator[tuple[Any, Result]]:
    """Run ``jobs`` (ticket, case) on ``count`` workers; yield (ticket, result) as they end.

    Raises:
        PoolError: A worker could not start.
    """
    pending = iter(jobs)
    workers = [_Worker(number, folder) for number in range(count)]
    exhausted = False
    try:
        while True:
            for worker in workers:
                if worker.ticket is None and not exhausted:
                    job = next(pending, None)
                    if job is None:
                        exhausted = True
                    else:
                        if worker.process.poll() is not None:  # died while idle
                            worker.stop()
                            worker.start()
                        worker.send(*job)
            busy = [w for w in workers if w.ticket is not None]
            if not busy:
                return
            _wait_any(busy)
            for worker in busy:
                result = _poll(worker)
                if result is None:
                    continue
                ticket = worker.ticket
                worker.ticket = None
                if worker.process.poll() is not None or worker.served >= CASES_PER_WORKER:
                    worker.stop()
                    worker.start()
                yield ticket, result
    finally:
        for worker in workers:
            worker.stop()


def _wait_any(busy: list[_Worker]) -> None:
    """Wait until a busy worker has output or its deadline passes (at most 0.5 s)."""
    with selectors.DefaultSelector() as selector:
        for worker in busy:
            selector.register(worker._out, selectors.EVENT_READ)
        selector.select(0.5)
