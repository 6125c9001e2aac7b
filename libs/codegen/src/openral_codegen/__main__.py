"""``python -m openral_codegen export|check`` (what ``just schema-export/-check`` run)."""

from __future__ import annotations

import sys

from openral_codegen.export import check, export
from openral_codegen.models import CodegenError


def main(argv: list[str]) -> int:
    """Run ``export`` or ``check``; returns the process exit code."""
    if argv not in (["export"], ["check"]):
        print("usage: python -m openral_codegen export|check", file=sys.stderr)
        return 2
    try:
        if argv == ["export"]:
            changed = export()
            print("\n".join(f"wrote {p}" for p in changed) or "generated tree already up to date")
            return 0
        problems = check()
    except CodegenError as error:
        print(f"error: {error}", file=sys.stderr)
        return 1
    if problems:
        print("generated tree is out of date; run `just schema-export`:", file=sys.stderr)
        print("\n".join(f"  {p}" for p in problems), file=sys.stderr)
        return 1
    print("generated tree is up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
