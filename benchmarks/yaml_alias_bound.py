"""What hostile YAML aliases cost the manifest loader before it refuses them.

Each case is a robot.yaml that repeats text through aliases; each runs ``load_robot`` in a
fresh Python process (so the memory figures are its own) and is timed once without and
measured once with tracemalloc. Run with ``python -m benchmarks.yaml_alias_bound``; the
table is printed: file size, time to refuse, peak Python allocations during the load and
the growth of the process's peak RSS.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

from rich.console import Console
from rich.table import Table


def _long_string(length: int, written: int, aliases: int) -> str:
    head = f'name: &a "{"x" * length}"\nnumbers: [{", ".join(["1"] * written)}]\njoints:\n'
    return head + "  - *a\n" * aliases


def _laughs(levels: int) -> str:
    lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for level in range(1, levels + 1):
        lines.append(f"a{level}: &a{level} [{','.join([f'*a{level - 1}'] * 10)}]")
    return "\n".join(lines) + "\n"


CASES = {
    "10 KiB string, 140k aliases": _long_string(10 * 1024, 0, 140_000),
    "100 KiB string, 2k values, 20k aliases": _long_string(100 * 1024, 2_000, 20_000),
    "1-char string, 140k aliases": _long_string(1, 0, 140_000),
    "billion laughs, 9 levels": _laughs(9),
}
"""Case name → file text (the second is the shape the fuzzer found: 164 KB, 2.0 GB)."""


def measure(file: Path) -> dict[str, float | str]:
    """Time and memory of refusing ``file`` in this process, and the first line of the error."""
    from openral_core.errors import ManifestError
    from openral_core.loader import load_robot

    def refuse() -> str:
        try:
            load_robot(file, check_folder_name=False)
        except ManifestError as error:
            return str(error).splitlines()[0].replace(f"{file}:", "")
        return "loaded"

    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    started = time.perf_counter()
    message = refuse()
    elapsed_s = time.perf_counter() - started
    rss_growth_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss_before
    tracemalloc.start()
    refuse()
    _, peak_bytes = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return {
        "ms": elapsed_s * 1e3,
        "peak_mb": peak_bytes / 1e6,
        "rss_mb": rss_growth_kb / 1e3,
        "error": message,
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--one", type=Path, help=argparse.SUPPRESS)  # child: measure a file
    args = parser.parse_args()
    if args.one is not None:
        print(json.dumps(measure(args.one)))
        return 0
    table = Table(title="Refusing alias-heavy manifests (load_robot, one process per case)")
    for column in ("case", "file KB", "refused in ms", "peak MB", "RSS growth MB", "error"):
        table.add_column(column, justify="left" if column in ("case", "error") else "right")
    with tempfile.TemporaryDirectory() as folder:
        for name, text in CASES.items():
            file = Path(folder) / "robot.yaml"
            file.write_text(text, encoding="utf-8")
            child = [sys.executable, "-m", "benchmarks.yaml_alias_bound", "--one", str(file)]
            row = json.loads(subprocess.run(child, capture_output=True, check=True).stdout)
            table.add_row(
                name,
                f"{file.stat().st_size / 1e3:.0f}",
                f"{row['ms']:.0f}",
                f"{row['peak_mb']:.1f}",
                f"{row['rss_mb']:.1f}",
                str(row["error"])[:70],
            )
    Console(width=200).print(table)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
