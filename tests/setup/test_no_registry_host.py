"""The repository reaches package registries only through their clients, by package name.

No tracked file names a registry's host: installs go through ``uv``/``pip`` (PyPI),
``npm`` and ``apt-get`` with package names and pinned versions/hashes
(``requirements.lock``, ``bootstrap``), never through an address written here.
"""

from __future__ import annotations

import re
import subprocess

from tests.conftest import REPO

# Joined at run time so that this file does not name the hosts it looks for.
_HOSTS = [
    ("pypi", "org"),
    ("pythonhosted", "org"),
    ("npmjs", "org"),
    ("npmjs", "com"),
    ("yarnpkg", "com"),
    ("jsdelivr", "net"),
    ("unpkg", "com"),
    ("deb.debian", "org"),
    ("security.debian", "org"),
    ("archive.ubuntu", "com"),
    ("conda.anaconda", "org"),
    ("crates", "io"),
    ("proxy.golang", "org"),
]
REGISTRY_HOST = re.compile("|".join(re.escape(".".join(host)) for host in _HOSTS), re.I)


def _tracked_text_files() -> list[str]:
    listed = subprocess.run(
        ["git", "ls-files", "-z"], cwd=REPO, capture_output=True, check=True
    ).stdout.decode()
    return [name for name in listed.split("\0") if name]


def test_no_tracked_file_names_a_registry_host() -> None:
    hits = []
    for name in _tracked_text_files():
        path = REPO / name
        if not path.is_file():
            continue
        data = path.read_bytes()
        if b"\0" in data[:8192]:
            continue  # binary: pictures, meshes
        for number, line in enumerate(data.decode("utf-8", "replace").splitlines(), 1):
            if REGISTRY_HOST.search(line):
                hits.append(f"{name}:{number}: {line.strip()[:120]}")
    assert not hits, "registry hosts in the tree:\n" + "\n".join(hits)


def test_the_pattern_finds_a_host_where_one_is_written() -> None:
    assert REGISTRY_HOST.search("url = https://" + ".".join(_HOSTS[1]) + "/packages/x.whl")
    assert not REGISTRY_HOST.search("pip install mujoco==3.8.1")


def test_mermaid_comes_from_npm_by_name_and_is_checked_against_its_pinned_hash() -> None:
    bootstrap = (REPO / "bootstrap").read_text("utf-8")
    assert 'npm pack --silent "mermaid@$MERMAID_VERSION"' in bootstrap
    assert re.search(r'^MERMAID_SHA512="[A-Za-z0-9+/]{86}=="$', bootstrap, re.M)
    assert "sha512 does not match the pinned one" in bootstrap


def test_the_lock_pins_every_distribution_with_hashes() -> None:
    lock = (REPO / "requirements.lock").read_text("utf-8")
    pins = re.findall(r"^([A-Za-z0-9_.-]+)==(\S+)", lock, re.M)
    assert len(pins) > 100
    blocks = re.split(r"\n(?=[A-Za-z0-9_.-]+==)", lock.strip())
    assert all("--hash=sha256:" in block for block in blocks if "==" in block.split("\n")[0])
