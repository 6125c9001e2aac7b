"""``python -m openral_codegen export|check|images``: the ``just`` schema and docs recipes."""

from __future__ import annotations

import sys

from openral_core.errors import OpenralError

from openral_codegen.export import REPO_ROOT, check, export
from openral_codegen.models import CodegenError

USAGE = "usage: python -m openral_codegen export|check|images [ROBOT_ID ...]"


def main(argv: list[str]) -> int:
    """Run ``export``, ``check`` or ``images``; returns the process exit code."""
    if (
        not argv
        or argv[0] not in ("export", "check", "images")
        or (argv[0] != "images" and len(argv) > 1)
    ):
        print(USAGE, file=sys.stderr)
        return 2
    try:
        if argv[0] == "export":
            changed = export()
            print("\n".join(f"wrote {p}" for p in changed) or "generated tree already up to date")
            return 0
        if argv[0] == "images":
            from openral_codegen.docs_images import write_images

            print("\n".join(f"wrote {p}" for p in write_images(REPO_ROOT, argv[1:] or None)))
            return 0
        problems = check()
    except (CodegenError, OpenralError) as error:
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
