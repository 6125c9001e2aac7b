"""The built site renders in headless Chromium: titles, the robot picture, no console errors.

The site (built once per session) is served from a local HTTP server; Chromium (the Debian
package, installed by ./bootstrap) opens the home page and the franka_panda page through
the DevTools protocol. Screenshots are saved to ``docs-screenshots/`` (not committed).
"""

from __future__ import annotations

import base64
import shutil
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import REPO
from tests.docs.cdp import CdpPage, Chromium
from tests.docs.conftest import BuiltSite

SCREENSHOTS = REPO / "docs-screenshots"
WINDOW = (1280, 900)
"""Browser viewport [px]."""
LOAD_TIMEOUT_S = 60.0


@dataclass(frozen=True)
class Visit:
    """What a page looked like once loaded."""

    title: str
    checks: dict[str, Any]
    errors: list[str]


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:
        """Keep the test output clean."""


@pytest.fixture(scope="module")
def site_url(built_site: BuiltSite) -> Iterator[str]:
    """The built site served on a free localhost port."""
    assert built_site.returncode == 0, built_site.log
    handler = partial(_QuietHandler, directory=str(built_site.site))
    server = ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}/"
    server.shutdown()
    thread.join()


@pytest.fixture(scope="module")
def page(tmp_path_factory: pytest.TempPathFactory) -> Iterator[CdpPage]:
    """A page of a fresh headless Chromium."""
    executable = shutil.which("chromium")
    if executable is None:
        pytest.fail(
            "chromium is not installed; the screenshot test needs the Debian package "
            "(`apt-get install chromium` as root, or run ./bootstrap as root)"
        )
    browser = Chromium(executable, tmp_path_factory.mktemp("chromium-profile"), WINDOW)
    session = browser.page()
    for domain in ("Page", "Runtime", "Log"):
        session.call(f"{domain}.enable")
    try:
        yield session
    finally:
        session.close()
        browser.close()


CHECKS = """({
  robotPictures: Array.from(document.images)
    .filter(i => i.src.includes('/images/robots/'))
    .map(i => ({src: i.src.split('/').pop(), complete: i.complete, width: i.naturalWidth})),
  darkModeToggle: !!document.querySelector('input[data-md-color-scheme="slate"]'),
  searchBox: !!document.querySelector('input.md-search__input'),
  copyButtons: document.querySelectorAll('button.md-code__button[data-md-type="copy"]').length,
  editLink: (document.querySelector('a.md-content__button[href*="/edit/"]') || {}).href || '',
})"""


def _visit(page: CdpPage, url: str, name: str) -> Visit:
    page.events.clear()
    page.call("Page.navigate", url=url)
    page.wait_for_event("Page.loadEventFired", LOAD_TIMEOUT_S)
    page.evaluate("new Promise(done => requestAnimationFrame(() => setTimeout(done, 300)))")
    SCREENSHOTS.mkdir(exist_ok=True)
    shot = page.call("Page.captureScreenshot", format="png")
    (SCREENSHOTS / f"{name}.png").write_bytes(base64.b64decode(shot["data"]))
    size = page.call("Page.getLayoutMetrics")["cssContentSize"]
    clip = {"x": 0, "y": 0, "width": size["width"], "height": size["height"], "scale": 1}
    full = page.call("Page.captureScreenshot", format="png", clip=clip, captureBeyondViewport=True)
    (SCREENSHOTS / f"{name}-full.png").write_bytes(base64.b64decode(full["data"]))
    errors = []
    for event in page.events:
        params = event.get("params", {})
        if event.get("method") == "Runtime.consoleAPICalled" and params["type"] == "error":
            errors.append(" ".join(str(a.get("value", a)) for a in params["args"]))
        elif event.get("method") == "Runtime.exceptionThrown":
            errors.append(str(params["exceptionDetails"].get("text")))
        elif event.get("method") == "Log.entryAdded" and params["entry"]["level"] == "error":
            errors.append(f"{params['entry']['text']} ({params['entry'].get('url', '')})")
    return Visit(page.evaluate("document.title"), page.evaluate(CHECKS), errors)


def test_home_page_renders_without_errors(page: CdpPage, site_url: str) -> None:
    visit = _visit(page, site_url, "home")
    assert visit.title == "openral"
    assert not visit.errors, visit.errors
    assert visit.checks["robotPictures"] == [
        {"src": "franka_panda.png", "complete": True, "width": 480}
    ]
    assert visit.checks["darkModeToggle"] and visit.checks["searchBox"]
    assert (SCREENSHOTS / "home.png").stat().st_size > 10_000


def test_franka_page_shows_its_picture_without_errors(page: CdpPage, site_url: str) -> None:
    visit = _visit(page, f"{site_url}robots/franka_panda/", "franka_panda")
    assert visit.title == "Franka Emika Panda - openral"
    assert not visit.errors, visit.errors
    assert visit.checks["robotPictures"] == [
        {"src": "franka_panda.png", "complete": True, "width": 480}
    ]
    assert visit.checks["copyButtons"] > 0
    assert visit.checks["editLink"].endswith("/edit/main/docs/robots/franka_panda.md")
    assert Path(SCREENSHOTS / "franka_panda-full.png").stat().st_size > 50_000


def test_architecture_diagram_is_drawn_offline(page: CdpPage, site_url: str) -> None:
    """Mermaid comes from the site itself (fetched by ./bootstrap), not from a CDN."""
    vendored = Path(__file__).parents[2] / "docs" / "javascripts" / "vendor" / "mermaid.min.js"
    assert vendored.is_file(), f"{vendored} is missing: ./bootstrap fetches it"
    visit = _visit(page, f"{site_url}architecture/", "architecture")
    assert not visit.errors, visit.errors
    # Material draws each diagram into a closed shadow root of a div.mermaid that replaces
    # the <pre class="mermaid"> source block; an undrawn diagram stays a <pre>.
    drawn = page.evaluate(
        "({source: document.querySelectorAll('pre.mermaid').length, "
        "drawn: Array.from(document.querySelectorAll('div.mermaid'))"
        ".map(d => Math.round(d.getBoundingClientRect().height))})"
    )
    assert drawn["source"] == 0 and drawn["drawn"], drawn
    assert all(height > 150 for height in drawn["drawn"]), drawn
