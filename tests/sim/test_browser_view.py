"""Tests for browser_view.py and viewer_page.py: where the view listens, and opening it again.

Every socket a view listens on (its page and its data stream) is bound to 127.0.0.1, read
from the kernel's socket tables for this process's own sockets, and the page answers there;
closing the view stops both. A port another process holds is refused with its address
before Rerun starts (Rerun itself would only log it); a view closed and opened again on the
same port (a deploy graph deactivated and activated) serves again. Rerun's page files are
copied once into a folder, and found there afterwards.
"""

from __future__ import annotations

import http.client
import socket
import time
from pathlib import Path

import pytest
from openral_sim.browser_view import BrowserView, ViewPorts, ViewUnavailable
from openral_sim.viewer_page import FILES, viewer_files

from tests.docs.headless_chromium import listening
from tests.docs.view_screenshot import free_port_pair


def test_a_view_opened_again_on_its_port_serves_again() -> None:
    port = free_port_pair()
    for title in ("first", "again", "and again"):
        view = BrowserView(None, title=title, ports=ViewPorts(web=port))
        assert listening(port) == listening(port + 1) == ["127.0.0.1"]
        view.transform("world/base", (0.1, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), None)
        view.close()


@pytest.mark.parametrize("which", [0, 1], ids=["page", "data stream"])
def test_a_taken_port_is_refused_with_its_address(which: int) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(ViewUnavailable, match=rf"cannot listen on 127\.0\.0\.1:{port} "):
            BrowserView(None, title="taken", ports=ViewPorts(web=port - which))


def own_listening_sockets() -> set[tuple[str, int]]:
    """(address, port) of every TCP socket of this process in LISTEN state, IPv4 and IPv6
    (/proc/net/tcp and tcp6 rows whose inode is one of this process's open files)."""
    inodes = set()
    for fd in Path("/proc/self/fd").iterdir():
        try:
            target = str(fd.readlink())
        except OSError:  # closed since the listing
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    found = set()
    for table, family in (("tcp", socket.AF_INET), ("tcp6", socket.AF_INET6)):
        for line in Path(f"/proc/net/{table}").read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == "0A" and fields[9] in inodes:  # 0A: LISTEN
                address, port = fields[1].split(":")
                raw = b"".join(chunk[::-1] for chunk in _words(bytes.fromhex(address)))
                found.add((socket.inet_ntop(family, raw), int(port, 16)))
    return found


def _words(raw: bytes) -> list[bytes]:
    """The kernel prints an address as 32-bit words in host (little-endian) order."""
    return [raw[i : i + 4] for i in range(0, len(raw), 4)]


def test_every_socket_the_view_listens_on_is_loopback_and_the_page_answers(
    capfd: pytest.CaptureFixture[str],
) -> None:
    port = free_port_pair()
    before = own_listening_sockets()
    view = BrowserView(None, title="loopback", ports=ViewPorts(web=port))
    try:
        opened = own_listening_sockets() - before
        assert opened == {("127.0.0.1", port), ("127.0.0.1", port + 1)}, opened
        connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
        connection.request("GET", view.ports.url.removeprefix(f"http://127.0.0.1:{port}"))
        page = connection.getresponse()
        body = page.read()
        assert page.status == 200 and page.getheader("Content-Type") == "text/html"
        assert body.lstrip().lower().startswith(b"<!doctype html>") and b"re_viewer.js" in body
        connection.request("GET", "/re_viewer_bg.wasm")
        wasm = connection.getresponse()
        assert wasm.status == 200 and wasm.getheader("Content-Type") == "application/wasm"
        assert wasm.read(4) == b"\0asm"
        connection.close()
    finally:
        view.close()
    assert ("127.0.0.1", port) not in own_listening_sockets() and listening(port) == []
    deadline = time.monotonic() + 5.0  # Rerun stops its data stream on a thread of its own
    while own_listening_sockets() - before and time.monotonic() < deadline:
        time.sleep(0.05)
    assert own_listening_sockets() - before == set()
    assert capfd.readouterr().err == ""  # a client leaving mid-answer is no traceback


def test_the_page_files_are_copied_once_into_a_folder(tmp_path: Path) -> None:
    folder = viewer_files(tmp_path)
    assert sorted(p.name for p in folder.iterdir()) == sorted(FILES)
    assert (folder / "re_viewer_bg.wasm").read_bytes()[:4] == b"\0asm"
    written = {p.name: p.stat().st_mtime_ns for p in folder.iterdir()}
    assert viewer_files(tmp_path) == folder
    assert {p.name: p.stat().st_mtime_ns for p in folder.iterdir()} == written
    assert [p.name for p in folder.parent.iterdir()] == [folder.name]  # no partial copy left
