"""Screenshots of a page in headless Chromium, taken after the page had real time to draw.

Chromium's own ``--screenshot`` captures at the load event, before a Wasm app such as
Rerun's viewer has compiled and drawn; so the browser is started with a DevTools port and
driven over its WebSocket: open the page, wait, capture. Chromium is the system package
``./bootstrap`` installs; flags as the machine notes say (no sandbox as root, no background
networking on a closed network, SwiftShader for WebGL without a GPU).
"""

from __future__ import annotations

import base64
import json
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any

import websocket

FLAGS = (
    "--headless", "--no-sandbox", "--enable-unsafe-swiftshader", "--use-angle=swiftshader",
    "--disable-quic", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--hide-scrollbars",
)  # fmt: skip


def free_port() -> int:
    """A TCP port nothing listens on at the moment (the OS's pick)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def listening(port: int) -> list[str]:
    """The local IPv4 addresses listening on TCP ``port`` (from /proc/net/tcp)."""
    found = []
    for line in Path("/proc/net/tcp").read_text().splitlines()[1:]:
        fields = line.split()
        address, hex_port = fields[1].split(":")
        if int(hex_port, 16) == port and fields[3] == "0A":  # 0A: LISTEN
            found.append(socket.inet_ntoa(bytes.fromhex(address)[::-1]))
    return found


def chromium() -> str | None:
    """The Chromium executable, or None when the machine has none."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


class Page:
    """One tab, driven over the DevTools protocol."""

    def __init__(self, ws_url: str) -> None:
        self._ws = websocket.create_connection(ws_url, timeout=60)
        self._id = 0

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        """Send one command and return its result (events in between are skipped)."""
        self._id += 1
        self._ws.send(json.dumps({"id": self._id, "method": method, "params": params}))
        while True:
            reply = json.loads(self._ws.recv())
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return dict(reply.get("result", {}))

    def screenshot(self, path: Path) -> None:
        """Write the tab's viewport as a PNG."""
        data = self.call("Page.captureScreenshot", format="png")["data"]
        path.write_bytes(base64.b64decode(data))

    def close(self) -> None:
        self._ws.close()


@contextmanager
def open_page(url: str, width: int = 1400, height: int = 800) -> Iterator[Page]:
    """Headless Chromium showing ``url`` in a ``width`` by ``height`` window."""
    executable = chromium()
    assert executable, "chromium is missing: ./bootstrap installs it"
    port = free_port()
    # Chromium's helpers (renderer, GPU, crash handler) outlive its main process for a while and
    # keep writing to the profile: they share its session, which is killed as a whole.
    with tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as profile:
        size = f"--window-size={width},{height}"
        debug = f"--remote-debugging-port={port}"
        command = [executable, *FLAGS, debug, f"--user-data-dir={profile}", size, url]
        process = subprocess.Popen(
            command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
        )
        try:
            page = Page(_page_socket(port))
            try:
                yield page
            finally:
                page.close()
        finally:
            _end_session(process)


def _end_session(process: subprocess.Popen[bytes]) -> None:
    """Stop Chromium and every helper it started (they share its session)."""
    with suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGTERM)
    try:
        process.wait(timeout=20)
    finally:
        with suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)


def _page_socket(port: int, timeout_s: float = 30.0) -> str:
    """The WebSocket address of the browser's first tab, once DevTools answers."""
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json", timeout=5) as answer:
                tabs = [t for t in json.load(answer) if t.get("type") == "page"]
            if tabs:
                return str(tabs[0]["webSocketDebuggerUrl"])
        except OSError:
            pass
        if time.monotonic() > deadline:
            raise TimeoutError(f"Chromium's DevTools did not answer on port {port}")
        time.sleep(0.2)
