"""Run the commands of a tutorial page, in order, in a fresh copy of the repository.

Conventions a tutorial follows so that it can be run (docs/contributing-docs.md repeats
them for writers):

- A fenced ``console`` block holds commands, each on a line starting with ``$ `` (a line
  ending in ``\\`` continues on the next). They run from the repository root with bash, one
  shell per command, so ``cd`` and ``export`` do not carry over.
- The other lines of a console block are the output of the command above them (stdout and
  stderr), shown in full: line for line, in order, blank lines aside. Within a line runs
  of white space (and of one box-drawing rule character) compare as one and ``…`` stands
  for any text; a line holding only ``⋮`` stands for any number of lines, the one way to
  leave lines out (``tests/docs/tutorial_output.py``).
- A command must exit 0, unless it ends with a comment ``# exit status N``.
- A command ending in ``&`` starts in the background; when lines follow it, the run waits
  until its output begins with them. ``kill -INT %N`` signals background job N (numbered
  from 1 in start order), ``wait`` or ``wait %N`` waits for jobs not yet waited for (they
  must exit 0); the lines after it are the rest of their output, in job order.
- The run starts from a copy of the repository without what the tutorial itself creates:
  every file a titled block writes, and the folder of each robot it scaffolds
  (``openral robot scaffold … --name <id>``), are removed from the copy and the generated
  tree is exported again. So a reader who completed a tutorial and committed its result
  can still run it, and its test, as written.
- A fenced block with ``title="<path>"`` is written to that path (relative to the
  repository root) when the run reaches it; other blocks are only shown.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from tests.docs.tutorial_output import (
    match_all,
    match_prefix,
    mismatch,
    printed_lines,
)

FOREGROUND_TIMEOUT_S = 300.0
"""Longest a foreground command may run (a full `just docs` on a loaded machine)."""
READY_TIMEOUT_S = 180.0
"""Longest a background command may take to print the lines the tutorial waits for."""
WAIT_TIMEOUT_S = 180.0
"""Longest ``wait`` blocks for a background command to exit."""
COPY_IGNORE = shutil.ignore_patterns(
    ".git",
    ".venv",
    ".tools",
    "site",
    "docs-screenshots",
    "out",
    "o",
    "__pycache__",
    ".pytest_cache",
    ".mypy_cache",
    ".ruff_cache",
    ".hypothesis",
    "MUJOCO_LOG.TXT",
)

_FENCE = re.compile(r"^(`{3,})\s*([\w+-]*)(.*)$")
_TITLE = re.compile(r'title="([^"]+)"')
_EXIT = re.compile(r"\s#\s*exit status (\d+)\s*$")
_JOB = re.compile(r"^(?:kill(?:\s+-(\w+))?|wait)\s+%(\d+)$")


@dataclass
class Command:
    """One ``$ `` line of a console block and the output lines shown under it."""

    text: str
    where: str
    expected: list[str] = field(default_factory=list)
    exit_status: int = 0
    background: bool = False


@dataclass(frozen=True)
class FileWrite:
    """A code block titled with a path: its content is written to that path."""

    path: str
    content: str
    where: str


Step = Command | FileWrite


def parse_tutorial(markdown: str, name: str) -> list[Step]:
    """The commands and file writes of a tutorial page, in page order."""
    steps: list[Step] = []
    lines = markdown.splitlines()
    index = 0
    while index < len(lines):
        opening = _FENCE.match(lines[index])
        if not opening:
            index += 1
            continue
        fence, language, info = opening.groups()
        start = index + 1
        index = start
        while index < len(lines) and lines[index].strip() != fence:
            index += 1
        body = lines[start:index]
        index += 1
        title = _TITLE.search(info)
        if title:
            steps.append(FileWrite(title.group(1), "\n".join(body) + "\n", f"{name}:{start}"))
        elif language == "console":
            steps += _console_commands(body, name, start + 1)
    return steps


def _console_commands(body: list[str], name: str, first_line: int) -> list[Command]:
    commands: list[Command] = []
    for offset, line in enumerate(body):
        if commands and commands[-1].text.endswith("\\"):
            commands[-1].text = commands[-1].text[:-1].rstrip() + " " + line.strip()
        elif line.startswith("$ "):
            commands.append(Command(line[2:].strip(), f"{name}:{first_line + offset}"))
        elif line.strip():
            if not commands:
                raise ValueError(f"{name}:{first_line + offset}: output before any `$ ` command")
            commands[-1].expected.append(line)
    for command in commands:
        status = _EXIT.search(command.text)
        if status:
            command.exit_status = int(status.group(1))
            command.text = command.text[: status.start()].rstrip()
        if command.text.endswith("&") and not command.text.endswith("&&"):
            command.background = True
            command.text = command.text[:-1].rstrip()
    return commands


_SCAFFOLD = re.compile(r"\bopenral robot scaffold\b.*\s--name[ =](\w+)")


def created_paths(steps: list[Step]) -> list[str]:
    """What the tutorial itself creates: titled blocks' files and scaffolded robot folders."""
    paths = [step.path for step in steps if isinstance(step, FileWrite)]
    for step in steps:
        scaffold = isinstance(step, Command) and _SCAFFOLD.search(step.text)
        if scaffold:
            paths.append(f"robots/{scaffold.group(1)}")
    return paths


def remove_created(sandbox: Path, steps: list[Step]) -> list[str]:
    """Remove from ``sandbox`` what ``steps`` create; the paths that were there."""
    removed = []
    for relative in created_paths(steps):
        target = sandbox / relative
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()
        else:
            continue
        removed.append(relative)
    return removed


def export_generated(sandbox: Path, env: dict[str, str]) -> None:
    """``just schema-export`` in ``sandbox`` (``env`` must point Python at its sources):
    after a removal under ``robots/``, as robot pages list scenes and quote them."""
    subprocess.run(
        ["python", "-m", "openral_codegen", "export"],
        cwd=sandbox,
        env=env,
        capture_output=True,
        check=True,
        timeout=FOREGROUND_TIMEOUT_S,
    )


def copy_repository(source: Path, target: Path) -> Path:
    """A copy of the working tree at ``target``, sharing ``source``'s virtual environment."""
    shutil.copytree(source, target, ignore=COPY_IGNORE, symlinks=True)
    (target / ".venv").symlink_to(source / ".venv")
    return target


def sandbox_environment(sandbox: Path, venv_bin: Path, tools: list[Path]) -> dict[str, str]:
    """Environment in which ``openral`` and ``just`` use the sandbox's code and files."""
    sources = [sandbox / "generated"]
    sources += sorted(sandbox.glob("libs/*/src")) + sorted(sandbox.glob("apps/*/src"))
    path = [str(venv_bin), *(str(t) for t in tools), os.environ.get("PATH", "/usr/bin:/bin")]
    return {
        **os.environ,
        "PATH": os.pathsep.join(path),
        "PYTHONPATH": os.pathsep.join(str(s) for s in sources),
        "MUJOCO_GL": "egl",
        "NO_MKDOCS_2_WARNING": "1",
    }


@dataclass
class _Job:
    command: Command
    process: subprocess.Popen[bytes]
    log: Path
    shown: int = 0
    """Lines of its output the tutorial has accounted for so far."""
    waited: bool = False

    def output(self) -> str:
        return self.log.read_text("utf-8", errors="replace")

    def lines(self) -> list[str]:
        return printed_lines(self.output())


class TutorialRun:
    """Runs the steps of one tutorial in ``sandbox``; background jobs log to ``logs``."""

    def __init__(
        self,
        sandbox: Path,
        logs: Path,
        env: dict[str, str],
        *,
        prelude: str = "",
        report: Callable[[Step], None] | None = None,
    ) -> None:
        self.sandbox = sandbox
        self.logs = logs
        self.env = env
        self.prelude = prelude
        """Shell text run before each command (e.g. ``source .venv/bin/activate``)."""
        self.report = report
        """Called with each step before it runs."""
        self.jobs: list[_Job] = []

    def run(self, steps: list[Step]) -> None:
        """Run every step; raises AssertionError at the first one that misbehaves."""
        try:
            for step in steps:
                if self.report is not None:
                    self.report(step)
                if isinstance(step, FileWrite):
                    target = self.sandbox / step.path
                    target.parent.mkdir(parents=True, exist_ok=True)
                    target.write_text(step.content, "utf-8")
                elif step.background:
                    self._start(step)
                elif step.text == "wait" or step.text.startswith(("wait ", "kill ")):
                    self._job_control(step)
                else:
                    self._foreground(step)
        finally:
            self._stop_all()

    def _foreground(self, command: Command) -> None:
        started = time.monotonic()
        result = subprocess.run(
            ["bash", "-c", self.prelude + command.text],
            cwd=self.sandbox,
            env=self.env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            timeout=FOREGROUND_TIMEOUT_S,
            check=False,
        )
        output = result.stdout.decode("utf-8", errors="replace")
        elapsed = time.monotonic() - started
        if result.returncode != command.exit_status:
            raise AssertionError(
                f"{command.where}: `{command.text}` exited {result.returncode}, expected "
                f"{command.exit_status} (after {elapsed:.1f} s); output:\n{output}"
            )
        self._check_output(command, command.expected, output)

    def _start(self, command: Command) -> None:
        log = self.logs / f"job{len(self.jobs) + 1}.log"
        with log.open("wb") as sink:
            process = subprocess.Popen(
                ["bash", "-c", self.prelude + command.text],
                cwd=self.sandbox,
                env=self.env,
                stdout=sink,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )
        job = _Job(command, process, log)
        self.jobs.append(job)
        deadline = time.monotonic() + READY_TIMEOUT_S
        while (shown := match_prefix(command.expected, job.lines())) is None:
            if process.poll() is not None or time.monotonic() > deadline:
                state = "exited" if process.poll() is not None else "timed out"
                raise AssertionError(
                    f"{command.where}: background `{command.text}` {state} before printing "
                    f"{command.expected}; output:\n{job.output()}"
                )
            time.sleep(0.2)
        job.shown = shown

    def _job_control(self, command: Command) -> None:
        match = _JOB.match(command.text)
        if command.text == "wait":
            jobs = self.jobs
        elif match:
            number = int(match.group(2))
            if not 1 <= number <= len(self.jobs):
                raise AssertionError(f"{command.where}: no background job %{number}")
            jobs = [self.jobs[number - 1]]
        else:
            raise AssertionError(f"{command.where}: unsupported job control `{command.text}`")
        if command.text.startswith("kill"):
            name = (match.group(1) if match else None) or "TERM"
            number = getattr(signal, f"SIG{name}") if not name.isdigit() else int(name)
            for job in jobs:
                if job.process.poll() is None:
                    os.killpg(job.process.pid, number)
            return
        rest: list[str] = []
        for job in (job for job in jobs if not job.waited):
            try:
                code = job.process.wait(timeout=WAIT_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                raise AssertionError(
                    f"{command.where}: `{job.command.text}` still runs after "
                    f"{WAIT_TIMEOUT_S:.0f} s; output:\n{job.output()}"
                ) from None
            if code != job.command.exit_status:
                raise AssertionError(
                    f"{job.command.where}: background `{job.command.text}` exited {code}; "
                    f"output:\n{job.output()}"
                )
            job.waited = True
            rest += job.lines()[job.shown :]
        self._check_output(command, command.expected, "\n".join(rest))

    def _check_output(self, command: Command, expected: list[str], output: str) -> None:
        printed = printed_lines(output)
        if not match_all(expected, printed):
            raise AssertionError(
                f"{command.where}: output of `{command.text}` is not what the tutorial shows: "
                f"{mismatch(expected, printed)}; output:\n{output}"
            )

    def _stop_all(self) -> None:
        for job in self.jobs:
            if job.process.poll() is None:
                os.killpg(job.process.pid, signal.SIGKILL)
                job.process.wait()
