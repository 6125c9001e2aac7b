"""Tests for browser_view.py: where the view listens, and opening it again.

A view's data stream listens on 127.0.0.1 only; a port another process holds is refused
with its address before Rerun starts (Rerun itself would only log it); a view closed and
opened again on the same port (a deploy graph deactivated and activated) serves again,
reusing the page Rerun keeps serving for the life of the process.
"""

from __future__ import annotations

import socket

import pytest
from openral_sim.browser_view import BrowserView, ViewPorts, ViewUnavailable

from tests.docs.headless_chromium import listening
from tests.docs.view_screenshot import free_port_pair


def test_a_view_opened_again_on_its_port_serves_again() -> None:
    port = free_port_pair()
    for title in ("first", "again", "and again"):
        view = BrowserView(None, title=title, ports=ViewPorts(web=port))
        assert listening(port + 1) == ["127.0.0.1"]
        view.transform("world/base", (0.1, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), None)
        view.close()


def test_a_taken_port_is_refused_with_its_address() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        data = taken.getsockname()[1]  # the data stream's port (the page's is one below)
        with pytest.raises(ViewUnavailable, match=r"cannot listen on 127\.0\.0\.1:"):
            BrowserView(None, title="taken", ports=ViewPorts(web=data - 1))
