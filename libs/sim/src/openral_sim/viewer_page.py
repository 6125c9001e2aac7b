"""Rerun's web viewer page, served on one address only.

Rerun 0.41's Python API serves the page on every interface (``rr.serve_web_viewer`` takes no
address) from files embedded in its extension module; the wheel ships them as no files of
their own. The wheel's ``rerun`` executable does take an address (``--bind``), so
:func:`viewer_files` runs it once per Rerun version on a free 127.0.0.1 port, copies the
page's files from it into a folder and stops it; :class:`PageServer` then serves that folder
from a thread of this process on one ``host:port``, until :meth:`PageServer.close`.

The folder is ``rerun-web/VERSION`` under ``$XDG_CACHE_HOME/openral`` (else
``~/.cache/openral``; the system's temporary folder when that cannot be written). It is
written whole (a temporary folder renamed into place), so processes can share it.
"""

from __future__ import annotations

import functools
import http.client
import http.server
import importlib.util
import os
import shutil
import socket
import socketserver
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import rerun as rr

LOOPBACK = "127.0.0.1"
FILES: dict[str, str] = {
    "index.html": "text/html",
    "re_viewer.js": "text/javascript",
    "re_viewer_bg.wasm": "application/wasm",
    "sw.js": "text/javascript",
    "favicon.ico": "image/x-icon",
    "apple-touch-icon.png": "image/png",
    "signed-in": "text/html",
}
"""The files Rerun's page server answers, by name, with their content types."""
Request = socket.socket | tuple[bytes, socket.socket]
"""What :mod:`socketserver` hands a server per request (a TCP server: the socket)."""
START_TIMEOUT_S = 30.0
"""How long the ``rerun`` executable may take to listen [s]: about 20 ms once its binary is
in the page cache; its first start after install, from a cold disk on a machine busy with
the test suite, took more than 10 s once."""
POLL_S = 0.05
"""How often the page server looks for :meth:`PageServer.close` [s]."""


class ViewUnavailable(RuntimeError):
    """The browser view cannot start (Rerun missing, a port taken)."""


def viewer_files(root: Path | None = None) -> Path:
    """The folder holding :data:`FILES` for the installed Rerun, copied from its ``rerun``
    executable the first time (about 0.2 s and 43 MB); ``root`` replaces the cache folder.

    Raises:
        ViewUnavailable: No folder can be written, or the executable serves no files.
    """
    roots = [root] if root is not None else _cache_roots()
    for base in roots:
        folder = base / "rerun-web" / rr.__version__
        if _complete(folder):
            return folder
        try:
            folder.parent.mkdir(parents=True, exist_ok=True)
            staging = Path(tempfile.mkdtemp(prefix=".partial-", dir=folder.parent))
        except OSError:
            continue
        try:
            _download(staging)
            if folder.exists() and not _complete(folder):  # a damaged copy
                shutil.rmtree(folder, ignore_errors=True)
            try:
                staging.rename(folder)
            except OSError:  # another process put its copy there first
                if not _complete(folder):
                    raise ViewUnavailable(f"cannot write the viewer's files to {folder}") from None
        finally:
            shutil.rmtree(staging, ignore_errors=True)
        return folder
    raise ViewUnavailable(f"cannot write the viewer's files under {', '.join(map(str, roots))}")


def _cache_roots() -> list[Path]:
    base = os.environ.get("XDG_CACHE_HOME", "").strip() or str(Path.home() / ".cache")
    return [Path(base) / "openral", Path(tempfile.gettempdir()) / f"openral-{os.getuid()}"]


def _complete(folder: Path) -> bool:
    return all((folder / name).is_file() for name in FILES)


def _download(folder: Path) -> None:
    """Copy :data:`FILES` into ``folder`` from the wheel's ``rerun`` executable, serving
    them on a free loopback port (given a data stream's address, it starts no server of
    its own for data)."""
    spec = importlib.util.find_spec("rerun_cli")
    if spec is None or spec.origin is None:
        raise ViewUnavailable("rerun-sdk's rerun executable is missing (rerun_cli)")
    executable = Path(spec.origin).parent / "rerun"
    port = _free_port()
    command = [str(executable), "--serve-web", "--bind", LOOPBACK, "--web-viewer-port",
               str(port), f"rerun+http://{LOOPBACK}:{port + 1}/proxy"]  # fmt: skip
    try:
        process = subprocess.Popen(
            command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
        )
    except OSError as error:
        raise ViewUnavailable(f"cannot run {executable} ({error.strerror})") from None
    connection = http.client.HTTPConnection(LOOPBACK, port, timeout=60)
    try:
        _wait_listening(process, port)
        for name in FILES:
            connection.request("GET", f"/{name}")
            response = connection.getresponse()
            if response.status != 200:
                raise ViewUnavailable(f"rerun's page server answered {response.status} for {name}")
            with (folder / name).open("wb") as out:
                shutil.copyfileobj(response, out)
    except (OSError, http.client.HTTPException) as error:
        raise ViewUnavailable(f"cannot copy the viewer's files from rerun: {error}") from None
    finally:
        connection.close()
        process.kill()
        process.communicate()


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind((LOOPBACK, 0))
        port: int = probe.getsockname()[1]
        return port


def _wait_listening(process: subprocess.Popen[bytes], port: int) -> None:
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        if process.poll() is not None:
            reason = (process.communicate()[1] or b"").decode(errors="replace").strip()
            last = reason.splitlines()[-1] if reason else "no output"
            raise ViewUnavailable(f"rerun's page server ended (exit {process.returncode}): {last}")
        try:
            socket.create_connection((LOOPBACK, port), timeout=0.5).close()
            return
        except OSError:
            time.sleep(0.02)
    raise ViewUnavailable(f"rerun's page server did not listen within {START_TIMEOUT_S:.0f} s")


class _Files(http.server.SimpleHTTPRequestHandler):
    """Answers with the files of its folder (``/`` is ``index.html``), writing no log."""

    def guess_type(self, path: str | os.PathLike[str]) -> str:
        """The content type Rerun's own server gives the file."""
        return FILES.get(Path(path).name, "application/octet-stream")

    def log_message(self, format: str, *args: object) -> None:
        """Write nothing (the base class writes every request to stderr)."""


class _Server(http.server.ThreadingHTTPServer):
    def server_bind(self) -> None:
        """Bind without the base class's reverse name look-up of the address."""
        socketserver.TCPServer.server_bind(self)
        self.server_name, self.server_port = str(self.server_address[0]), self.server_address[1]

    def handle_error(self, request: Request, client_address: Any) -> None:
        """Say nothing of a browser that left mid-answer (the base class prints a traceback
        to stderr); report anything else."""
        if not isinstance(sys.exc_info()[1], ConnectionError):
            super().handle_error(request, client_address)


class PageServer:
    """Serves a folder of :data:`FILES` on ``host:port`` only, from a daemon thread."""

    def __init__(self, folder: Path, host: str, port: int) -> None:
        """Start listening.

        Raises:
            ViewUnavailable: ``host:port`` is taken.
        """
        handler = functools.partial(_Files, directory=str(folder))
        try:
            self._server = _Server((host, port), handler)
        except OSError as error:
            raise ViewUnavailable(
                f"the view cannot listen on {host}:{port} ({error.strerror})"
            ) from None
        serve = functools.partial(self._server.serve_forever, poll_interval=POLL_S)
        self._thread = threading.Thread(target=serve, name=f"view page {port}", daemon=True)
        self._thread.start()

    def close(self) -> None:
        """Stop listening and end the serving thread (requests under way finish on their
        own threads)."""
        self._server.shutdown()
        self._server.server_close()
        self._thread.join()


__all__ = ["FILES", "PageServer", "ViewUnavailable", "viewer_files"]
