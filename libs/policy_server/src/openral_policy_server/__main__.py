"""``python -m openral_policy_server FILE.py:CLASS [--host H] [--port P]``: serve CLASS
(made with no arguments, once per connection) from FILE."""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path

from openral_policy_server.server import serve


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m openral_policy_server")
    parser.add_argument("policy", help="FILE.py:CLASS")
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=8765)
    args = parser.parse_args(argv)
    where, _, name = args.policy.rpartition(":")
    path = Path(where)
    if not path.is_file() or not name.isidentifier():
        parser.error(f"{args.policy!r}: expected FILE.py:CLASS with FILE an existing file")
    spec = importlib.util.spec_from_file_location(path.stem, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[path.stem] = module
    spec.loader.exec_module(module)
    factory = getattr(module, name, None)
    if not callable(factory):
        parser.error(f"{args.policy!r}: {path} has no class {name}")
    serve(factory, args.host, args.port)
    return 0


if __name__ == "__main__":
    sys.exit(main())
