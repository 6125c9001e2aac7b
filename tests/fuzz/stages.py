"""Run one fuzzed file through the real stages a user's file goes through.

A manifest: ``load`` (``load_robot``) → ``check`` (the ``openral robot check`` command,
in-process) → ``hal`` (``build_hal(loaded_robot(robot), mode="sim")``: connect, read_state,
send a hold action, one step, disconnect). A scene: ``load`` (``load_scene``) → ``scene``
(``build_hal(robot, mode="sim", scene=scene)`` with the seed's robot from robots/ and the
scene loaded once: connect, read_state, send ``hold_action()``, one idle step, disconnect).

A case stops at the first stage that refuses it. ``robot check`` reporting mismatches (a
table of fields, no error) is not a refusal: the HAL stage then has to refuse the manifest
itself, located. A case marked ``load_only`` stops after ``load`` (robosuite scenes in the
pytest test, whose build takes about 2 s).
"""

from __future__ import annotations

import re
import signal
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any

from openral_core import loaded_robot, open_robot_by_id
from openral_core.loader import load_robot, load_scene

from tests.fuzz.outcome import (
    HANG_SECONDS,
    Outcome,
    Result,
    classify,
    classify_lines,
    unlocated_lines,
)
from tests.fuzz.seeds import Kind

if TYPE_CHECKING:
    from openral_hal.protocol import RobotHal

StageHook = Callable[[str], None]
WARNING = "! "
"""How ``robot check`` marks a warning (a deprecated form, say): said, not a refusal."""
_SUMMARY = re.compile(
    r"^\d+ of \d+ robot\(s\) "
    r"(do not match their model(; \d+ could not be checked)?|could not be checked)$"
)
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


@dataclass(frozen=True)
class Case:
    """A fuzzed file ready to run: where it is, what it is and which robot it is for."""

    file: Path
    kind: Kind
    robot: str
    load_only: bool = False


class CheckRefused(Exception):
    """``robot check`` printed errors (the lines, without their ``✗`` mark)."""

    def __init__(self, lines: list[str]) -> None:
        super().__init__("\n".join(lines))
        self.lines = lines


class CaseTimeout(BaseException):
    """Raised in-process when a case overruns (a BaseException: no ``except Exception``
    in the library can swallow it)."""


def run_case(case: Case, on_stage: StageHook | None = None) -> Result:
    """Run ``case`` through its stages; every way it can end becomes a :class:`Result`.

    Args:
        case: The file and what it is.
        on_stage: Called with each stage's name as it starts (the worker reports it, so a
            hang or crash is blamed on the right stage).
    """
    stage = "load"

    def enter(name: str) -> None:
        nonlocal stage
        stage = name
        if on_stage is not None:
            on_stage(name)

    start = time.perf_counter()
    try:
        if case.kind == "manifest":
            _manifest_stages(case, enter)
        else:
            _scene_stages(case, enter)
    except KeyboardInterrupt:
        raise
    except CaseTimeout:
        return Result(Outcome.HANG, stage, f"over {HANG_SECONDS:g} s in {stage}")
    except CheckRefused as refused:
        result = classify_lines(refused.lines, stage, case.file)
    except BaseException as error:  # every other ending is what the fuzzer looks for
        result = classify(error, stage, case.file)
    else:
        result = Result(Outcome.OK, stage)
    seconds = time.perf_counter() - start
    if seconds > HANG_SECONDS:
        signature = f"over {HANG_SECONDS:g} s in {stage} (finished: {result.outcome})"
        return Result(Outcome.HANG, stage, signature, result.detail, seconds)
    return Result(result.outcome, result.stage, result.signature, result.detail, seconds)


def _manifest_stages(case: Case, enter: StageHook) -> None:
    from openral_hal.factory import build_hal
    from openral_hal.mujoco_arm import MujocoArmHAL

    enter("load")
    robot = load_robot(case.file)
    if case.load_only:
        return
    enter("check")
    robot_check(case.file)
    enter("hal")
    hal = build_hal(loaded_robot(robot), mode="sim")
    if not isinstance(hal, MujocoArmHAL):
        raise TypeError(f"build_hal without a scene gave {type(hal).__name__}")
    _drive(hal, lambda: hal.read_state().positions.copy(), lambda: hal.step())


def _scene_stages(case: Case, enter: StageHook) -> None:
    from openral_hal.factory import build_hal, can_tick

    enter("load")
    scene = load_scene(case.file)
    if case.load_only:
        return
    enter("scene")
    hal = build_hal(open_robot_by_id(case.robot), mode="sim", scene=scene)
    if not can_tick(hal):
        raise TypeError(f"build_hal with a scene gave {type(hal).__name__}")
    _drive(hal, lambda: hal.hold_action(), lambda: hal.tick(None))


def _drive(hal: RobotHal, hold: Callable[[], Any], step: Callable[[], Any]) -> None:
    """connect, read_state, send the hold action, step once, disconnect."""
    try:
        hal.connect()
        hal.read_state()
        hal.send_action(hold())
        step()
    except BaseException:
        with suppress(Exception):  # free the renderers; the first error is the finding
            hal.disconnect()
        raise
    hal.disconnect()


def robot_check(file: Path) -> None:
    """Run ``openral robot check <file>`` in-process.

    Raises:
        CheckRefused: The command printed errors (exit 1 with ``✗`` lines, or exit 2).
        Exception: Whatever the command raised, with its traceback.
    """
    from openral_cli.commands.robot import app
    from typer.testing import CliRunner

    result = CliRunner().invoke(app, ["check", str(file)])
    error = result.exception
    if error is not None and not isinstance(error, SystemExit):
        raise error
    if result.exit_code == 0:
        return
    printed = _ANSI.sub("", result.stderr).splitlines()
    warned = [line.removeprefix(WARNING) for line in printed if line.startswith(WARNING)]
    lines = [
        line.removeprefix("✗ ")
        for line in printed
        if not _SUMMARY.match(line) and not line.startswith(WARNING)
    ]
    if result.exit_code == 1 and not lines:
        if unlocated_lines("\n".join(warned), file) and warned:
            raise CheckRefused(warned)  # a warning must point into the file too
        return  # mismatches only: the HAL stage must refuse them at the manifest's fields
    raise CheckRefused(lines or [f"exit code {result.exit_code} and nothing printed"])


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`CaseTimeout` in the main thread after ``seconds`` (SIGALRM)."""

    def expire(signum: int, frame: FrameType | None) -> None:
        raise CaseTimeout

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
