"""What recording every topic costs: ``openral deploy sim`` alone against ``deploy sim
--record``, side by side.

Each round launches the franka tabletop twice (alone, then recording into a fresh bag) and
measures the CPU time of the deploy process and all its descendants (the recorder is a
child) over the same steady window (``--settle`` seconds after launch, for ``--window``
seconds), as a share of one core; and how many messages the recorder dropped (its summary
table). The difference of the medians is what recording costs. Run with
``just bench-record``; written to ``benchmarks/results/record_cost.json``.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

from benchmarks.deploy_launch import DEFAULT_SCENE, OPENRAL, deploy_env, tree_cpu_seconds, warm_up
from benchmarks.results_file import write_results

TARGET_EXTRA_CORE = 0.15
"""Recording may add at most this share of one core."""


def one_run(
    record: Path | None, settle_s: float, window_s: float, domain: int
) -> tuple[float, int]:
    """(CPU share of one core over the window, messages dropped) of one launch."""
    command = [str(OPENRAL), "deploy", "sim", "--no-viewer", "--config", str(DEFAULT_SCENE)]
    command += ["--duration", str(settle_s + window_s + 2.0), "--domain-id", str(domain)]
    if record is not None:
        command += ["--record", str(record)]
    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=deploy_env()
    )
    time.sleep(settle_s)
    start = tree_cpu_seconds(process.pid)
    time.sleep(window_s)
    share = (tree_cpu_seconds(process.pid) - start) / window_s
    out, _ = process.communicate(timeout=120)
    if process.returncode != 0:
        raise SystemExit(f"deploy sim exited {process.returncode}:\n{out}")
    return share, _dropped(out)


def _dropped(table: str) -> int:
    """The sum of the recorder table's last column (0 without a table)."""
    total = 0
    for line in table.splitlines():
        cells = [c.strip() for c in line.split("│")]
        if len(cells) == 6 and cells[4].isdigit():
            total += int(cells[4])
    return total


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--settle", type=float, default=6.0, help="seconds before the window")
    parser.add_argument("--window", type=float, default=20.0, help="seconds measured")
    args = parser.parse_args()
    warm_up(DEFAULT_SCENE)
    alone, recording, dropped = [], [], 0
    with tempfile.TemporaryDirectory() as scratch:
        for index in range(args.rounds):
            alone.append(one_run(None, args.settle, args.window, 60 + index)[0])
            share, lost = one_run(
                Path(scratch) / f"bag{index}", args.settle, args.window, 70 + index
            )
            recording.append(share)
            dropped += lost
    extra = statistics.median(recording) - statistics.median(alone)
    table = Table(title=f"franka tabletop, {args.rounds} rounds of {args.window:g} s (median)")
    for column in ("measure", "value"):
        table.add_column(column)
    table.add_row("deploy sim alone [% of one core]", f"{100 * statistics.median(alone):.1f}")
    table.add_row(
        "deploy sim --record [% of one core]", f"{100 * statistics.median(recording):.1f}"
    )
    table.add_row("recording adds [% of one core]", f"{100 * extra:.1f}")
    table.add_row("messages dropped (all rounds)", str(dropped))
    Console().print(table)
    path = write_results(
        "record_cost",
        {"alone": alone, "recording": recording, "extra_core": extra, "dropped": dropped},
    )
    verdict = "met" if extra <= TARGET_EXTRA_CORE and dropped == 0 else "NOT met"
    limit = f"≤ {100 * TARGET_EXTRA_CORE:.0f} % of one core"
    print(f"target: {limit} and no drops: {verdict}. Written to {path}.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
