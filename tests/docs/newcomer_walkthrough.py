"""A newcomer's first hour, replayed: fresh clone, fresh shell, only printed commands.

Run from a checkout, with nothing but the system Python (no environment set up yet)::

    python3 -m tests.docs.newcomer_walkthrough            # clone of this checkout's HEAD
    python3 -m tests.docs.newcomer_walkthrough --keep /tmp/newcomer

It clones the checkout into an empty folder and works there as a new user would, in the
environment of a new login shell (the machine's own variables; no virtual environment, no
project variables, no PATH entry into a checkout):

1. ``./bootstrap demo`` as the README prints it, until the graph is running; then SIGINT to
   that process alone, which must end it with status 0 within 2 s.
2. Every tutorial, in the order of the site's navigation, each command as printed, run in
   a new shell that first does what the README says (``source .venv/bin/activate``); the
   shown output is checked as the tutorial test checks it.
3. ``git add -A && git commit``: the user keeps what the tutorials made.
4. ``./bootstrap test``: the suite must still pass. Its exit status is this script's.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tests.docs.tutorial_runner import Command, FileWrite, Step, TutorialRun, parse_tutorial

CHECKOUT = Path(__file__).resolve().parents[2]
ACTIVATE = "source .venv/bin/activate\n"
"""What the README tells a new shell to run before the other commands."""
DEMO_READY = "running; stop with Ctrl-C"
DEMO_READY_TIMEOUT_S = 1800.0
"""A first ``./bootstrap`` installs everything: give it up to half an hour."""
DEMO_STOP_LIMIT_S = 2.0


def fresh_environment() -> dict[str, str]:
    """What a new login shell on this machine has: its certificates, proxies and locale,
    but no virtual environment, no project variables and nothing of the caller's PATH
    that points into a checkout (``.venv``, ``.tools``)."""
    dropped = ("VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME", "MUJOCO_GL", "COLUMNS", "LINES")
    env = {
        key: value
        for key, value in os.environ.items()
        if key not in dropped and not key.startswith(("OPENRAL_", "PYTEST_"))
    }
    system = [
        entry
        for entry in os.environ.get("PATH", "/usr/bin:/bin").split(os.pathsep)
        if entry and ".venv" not in entry and ".tools" not in entry
    ]
    env["PATH"] = os.pathsep.join(system)
    return env


def say(text: str) -> None:
    print(f"[walkthrough] {text}", flush=True)


def tutorial_pages(repo: Path) -> list[Path]:
    """The tutorials in the order the site's navigation lists them."""
    nav = (repo / "mkdocs.yml").read_text("utf-8")
    return [repo / "docs" / p for p in re.findall(r":\s*(tutorials/[\w-]+\.md)", nav)]


def run_demo(repo: Path, env: dict[str, str], logs: Path) -> float:
    """``./bootstrap demo`` until it is running, then SIGINT to its PID; seconds to exit."""
    say("./bootstrap demo")
    log = logs / "demo.log"
    with log.open("wb") as sink:
        demo = subprocess.Popen(
            ["./bootstrap", "demo"], cwd=repo, env=env, stdout=sink, stderr=subprocess.STDOUT
        )
    deadline = time.monotonic() + DEMO_READY_TIMEOUT_S
    while DEMO_READY not in log.read_text("utf-8", errors="replace"):
        if demo.poll() is not None or time.monotonic() > deadline:
            demo.kill()
            raise SystemExit(f"the demo never ran; its output:\n{log.read_text('utf-8')}")
        time.sleep(0.5)
    sent = time.monotonic()
    demo.send_signal(signal.SIGINT)
    try:
        code = demo.wait(timeout=30)
    except subprocess.TimeoutExpired:
        demo.kill()
        raise SystemExit("the demo ignored SIGINT for 30 s") from None
    took = time.monotonic() - sent
    print(log.read_text("utf-8", errors="replace"), end="")
    if code != 0 or took > DEMO_STOP_LIMIT_S:
        raise SystemExit(f"SIGINT to ./bootstrap demo: exit {code} after {took:.2f} s")
    say(f"demo stopped by SIGINT to its PID: exit 0 after {took:.2f} s")
    return took


def show(step: Step) -> None:
    if isinstance(step, FileWrite):
        say(f"  write {step.path}  ({step.where})")
    elif isinstance(step, Command):
        say(f"  $ {step.text}{' &' if step.background else ''}  ({step.where})")


def run_tutorials(repo: Path, env: dict[str, str], logs: Path) -> None:
    for page in tutorial_pages(repo):
        say(f"tutorial {page.relative_to(repo)}")
        steps = parse_tutorial(page.read_text("utf-8"), str(page.relative_to(repo)))
        started = time.monotonic()
        TutorialRun(repo, logs, env, prelude=ACTIVATE, report=show).run(steps)
        say(f"  done in {time.monotonic() - started:.0f} s")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--keep", type=Path, help="clone into this (empty or new) folder")
    parser.add_argument("--source", default=str(CHECKOUT), help="repository to clone")
    args = parser.parse_args(argv)
    base = args.keep or Path(tempfile.mkdtemp(prefix="openral-newcomer-"))
    repo, logs = base / "openral", base / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    env = fresh_environment()
    say(f"git clone {args.source} {repo}")
    subprocess.run(["git", "clone", "-q", args.source, str(repo)], check=True, env=env)
    run_demo(repo, env, logs)
    run_tutorials(repo, env, logs)
    say("git add -A && git commit  (keep what the tutorials made)")
    subprocess.run(["git", "add", "-A"], cwd=repo, check=True, env=env)
    commit = ["git", "-c", "user.name=Newcomer", "-c", "user.email=newcomer@localhost"]
    subprocess.run([*commit, "commit", "-q", "-m", "Tutorial results"], cwd=repo, env=env)
    subprocess.run(["git", "show", "--stat", "--format=%h %s", "HEAD"], cwd=repo, env=env)
    say("./bootstrap test")
    code = subprocess.run(["./bootstrap", "test"], cwd=repo, env=env, check=False).returncode
    say(f"./bootstrap test exited {code}")
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
