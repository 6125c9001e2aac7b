"""``openral ros record``: record a live graph into a rosbag2 bag (MCAP), or repair one.

The recording itself is :mod:`openral_nodes.bag_recorder` (raw subscriptions) and
:mod:`openral_nodes.bag_writer` (the writer thread); a killed recording is rebuilt by
:mod:`openral_nodes.bag_repair`. ``openral deploy sim --record DIR`` runs this command in
a child process, so recording never shares the control loop's interpreter.
"""

from __future__ import annotations

import signal
import threading
import time
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer
from openral_core.errors import OpenralError, escaped

from openral_cli.commands.ros import DomainId, _probe_node, app
from openral_cli.console import err, out
from openral_cli.ros_available import require_ros

if TYPE_CHECKING:
    from openral_nodes.bag_writer import BagWriter

POLL_S = 0.1
"""Interval between checks for a stop (signal, --duration, a full disk) [s]."""


@app.command("record")
def record(
    folder: Annotated[Path, typer.Argument(help="Bag folder to create.", show_default=False)],
    topics: Annotated[
        list[str] | None,
        typer.Argument(help="Topics to record.", show_default="every topic but hidden ones"),
    ] = None,
    overwrite: Annotated[
        bool, typer.Option("--overwrite", help="Replace FOLDER if it holds a bag already.")
    ] = False,
    repair: Annotated[
        bool,
        typer.Option("--repair", help="Rebuild FOLDER's bag after a killed recording; no ROS."),
    ] = False,
    duration: Annotated[
        float | None,
        typer.Option(
            "--duration", min=0.0, help="Stop after this many seconds.", show_default="Ctrl-C"
        ),
    ] = None,
    domain_id: DomainId = None,
) -> None:
    """Record the graph's topics into a rosbag2 bag in MCAP storage until Ctrl-C or SIGTERM.

    Every topic with a publisher is recorded (or only TOPICS), including topics that appear
    later; hidden ones (/rosout, /parameter_events, /_action/...) are left out. Each message
    is stored as its publisher serialised it, stamped with its receive time, together with
    the type's definition and hash and the publishers' QoS. At the end a table lists each
    topic's messages and any dropped. `--repair` rebuilds a bag whose recording was killed.

    Examples:

        openral ros record out/run1
        openral ros record out/arm /joint_states /tf --duration 30
        openral ros record out/run1 --repair
    """
    if repair:
        _repair(folder)
        return
    require_ros()
    from openral_nodes.bag_writer import new_bag_folder

    new_bag_folder(folder, overwrite)
    _record(folder, tuple(topics or ()), duration, domain_id)


def _record(
    folder: Path, topics: tuple[str, ...], duration: float | None, domain_id: int | None
) -> None:
    """Record until a signal, ``duration`` or a full disk; print the summary.

    Raises:
        OpenralError: Recording stopped early (the reason; the bag is closed).
    """
    from openral_nodes.bag_recorder import BagRecorder
    from openral_nodes.bag_writer import BagWriter

    stop = threading.Event()
    signals = (signal.SIGINT, signal.SIGTERM)
    previous = {sig: signal.signal(sig, lambda *_: stop.set()) for sig in signals}
    started = time.monotonic()
    try:
        writer = BagWriter(folder)
        try:
            with _probe_node(domain_id, events=True) as node:
                recorder = BagRecorder(node, writer, topics)
                err.print(f"recording into {folder}; stop with Ctrl-C", highlight=False)
                _wait(stop, writer, duration)
                missing = recorder.missing()
        finally:
            writer.close()
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    _summary(writer, folder, time.monotonic() - started, missing)
    if writer.stopped is not None:
        raise OpenralError(writer.stopped)


def _wait(stop: threading.Event, writer: BagWriter, duration: float | None) -> None:
    deadline = None if duration is None else time.monotonic() + duration
    while not stop.wait(POLL_S):
        if writer.stopped is not None or (deadline is not None and time.monotonic() >= deadline):
            return


def _summary(writer: BagWriter, folder: Path, elapsed_s: float, missing: list[str]) -> None:
    """The table of topics, then what was skipped and where the bag is."""
    from rich.table import Table

    table = Table(title=f"recorded {elapsed_s:.1f} s")
    for column in ("topic", "type", "messages", "dropped"):
        table.add_column(column, justify="right" if column in ("messages", "dropped") else "left")
    for name, tally in sorted(writer.tallies.items()):
        table.add_row(escaped(name), tally.msgtype, str(tally.written), str(tally.dropped))
    out.print(table, soft_wrap=False)
    for name, reason in sorted(writer.skipped.items()):
        out.print(f"not recorded: {escaped(name)}: {escaped(reason)}", markup=False)
    for name in missing:
        out.print(f"not recorded: {escaped(name)}: no publisher appeared", markup=False)
    total = sum(t.written for t in writer.tallies.values())
    size = sum(f.stat().st_size for f in folder.glob("*") if f.is_file()) / 2**20
    out.print(f"wrote {folder} ({total} messages, {size:.1f} MiB)", markup=False)


def _repair(folder: Path) -> None:
    from openral_nodes.bag_repair import repair

    repaired = repair(folder)
    total = sum(repaired.counts.values())
    out.print(
        f"repaired {folder}: {total} messages on {len(repaired.counts)} topics, "
        f"{repaired.span_s:.1f} s; the original is kept as *.mcap.truncated",
        markup=False,
    )
