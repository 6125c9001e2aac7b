"""What a new reader meets: every tutorial linked from the home page, numbers that agree,
a search that finds ROS names by their parts, and code blocks whose ends the copy button
does not cover.

The browser checks open the built site (``built_site``, once per session) in headless
Chromium, as ``test_screenshots.py`` does.
"""

from __future__ import annotations

import json
import re
import shutil
import threading
from collections.abc import Iterator
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import pytest

from tests.conftest import REPO
from tests.docs.cdp import CdpPage, Chromium
from tests.docs.conftest import BuiltSite

DOCS = REPO / "docs"
LOAD_TIMEOUT_S = 60.0


def test_home_page_lists_every_tutorial_in_navigation_order() -> None:
    linked = re.findall(r"\]\((tutorials/[\w-]+\.md)\)", (DOCS / "index.md").read_text())
    nav = re.findall(r":\s*(tutorials/[\w-]+\.md)", (REPO / "mkdocs.yml").read_text())
    on_disk = sorted(p.relative_to(DOCS).as_posix() for p in (DOCS / "tutorials").glob("*.md"))
    assert sorted(linked) == on_disk, f"docs/index.md links {linked}; the tutorials: {on_disk}"
    assert linked == nav


def test_mobile_tutorial_intro_drives_as_far_as_its_body_measures() -> None:
    text = (DOCS / "tutorials" / "mobile-sensing.md").read_text()
    intro, body = text.split("\n## ", 1)
    promised = re.search(r"drive the base (?:about\s+)?([\d.]+) m", intro)
    measured = re.search(r"about ([\d.]+) m:\n", body)
    odom_x = re.search(r"position:\n\s+x: ([\d.]+)…", body)
    assert promised and measured and odom_x, "the intro, the estimate or the /odom x moved"
    assert promised[1] == measured[1], f"intro {promised[1]} m, body {measured[1]} m"
    assert measured[1].startswith(odom_x[1]), f"/odom shows x: {odom_x[1]}…"


def _search_separator(built_site: BuiltSite) -> re.Pattern[str]:
    index = json.loads((built_site.site / "search" / "search_index.json").read_text())
    return re.compile(index["config"]["separator"])


@pytest.mark.parametrize(
    ("text", "tokens"),
    [
        ("/openral/estop", ["openral", "estop"]),
        ("<code>/openral/safe_action</code>", ["<code>", "openral", "safe", "action<", "code>"]),
        ("-p amplitude=0.3", ["p", "amplitude", "0.3"]),
        ("about 0.75 m.", ["about", "0.75", "m"]),
    ],
)
def test_search_splits_topics_and_names_at_slashes_and_underscores(
    built_site: BuiltSite, text: str, tokens: list[str]
) -> None:
    """The separator the browser's search tokenises with (Python and JavaScript agree here)."""
    assert built_site.returncode == 0, built_site.log
    assert [t for t in _search_separator(built_site).split(text) if t] == tokens


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:
        """Keep the test output clean."""


@pytest.fixture(scope="module")
def site_url(built_site: BuiltSite) -> Iterator[str]:
    """The built site served on a free localhost port."""
    assert built_site.returncode == 0, built_site.log
    server = ThreadingHTTPServer(
        ("127.0.0.1", 0), partial(_QuietHandler, directory=str(built_site.site))
    )
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}/"
    server.shutdown()
    thread.join()


@pytest.fixture(scope="module", params=[(1280, 900), (420, 900)], ids=["desktop", "phone"])
def page(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[CdpPage]:
    """A page of a fresh headless Chromium, at a desktop and at a phone's width."""
    executable = shutil.which("chromium")
    if executable is None:
        pytest.fail("chromium is not installed; ./bootstrap as root installs it")
    browser = Chromium(executable, tmp_path_factory.mktemp("chromium-profile"), request.param)
    session = browser.page()
    session.call("Page.enable")
    session.call("Runtime.enable")
    try:
        yield session
    finally:
        session.close()
        browser.close()


def _open(page: CdpPage, url: str) -> None:
    page.events.clear()
    page.call("Page.navigate", url=url)
    page.wait_for_event("Page.loadEventFired", LOAD_TIMEOUT_S)
    page.evaluate("new Promise(done => requestAnimationFrame(() => setTimeout(done, 300)))")


def _run(page: CdpPage, script: str) -> Any:
    """Await ``script`` (an async expression) in the page and return its JSON value."""
    result = page.call("Runtime.evaluate", expression=script, awaitPromise=True, returnByValue=True)
    assert "exceptionDetails" not in result, result["exceptionDetails"]
    return result["result"].get("value")


COVERED = """(() => {
  const covered = [];
  let blocks = 0;
  for (const pre of document.querySelectorAll('.md-typeset pre')) {
    const code = pre.querySelector(':scope > code');
    const nav = pre.querySelector(':scope > .md-code__nav');
    if (!code || !nav) continue;
    blocks++;
    code.scrollLeft = code.scrollWidth;  // scrolled to the end of its longest line
    const button = nav.getBoundingClientRect();
    const walker = document.createTreeWalker(code, NodeFilter.SHOW_TEXT);
    let hit = false;
    for (let node = walker.nextNode(); node && !hit; node = walker.nextNode()) {
      for (let i = 0; i < node.length && !hit; i++) {
        if (/\\s/.test(node.data[i])) continue;
        const range = document.createRange();
        range.setStart(node, i);
        range.setEnd(node, i + 1);
        const c = range.getBoundingClientRect();
        hit = c.width > 0 && c.right > button.left && c.left < button.right
          && c.bottom > button.top && c.top < button.bottom;
      }
    }
    if (hit) covered.push(code.textContent.slice(0, 60));
    code.scrollLeft = 0;
  }
  return {blocks, covered};
})()"""

PAGES_WITH_LONG_LINES = [
    *(f"tutorials/{p.stem}/" for p in sorted((DOCS / "tutorials").glob("*.md"))),
    "reference/robot/",
    "reference/sim/",
]


@pytest.mark.parametrize("path", PAGES_WITH_LONG_LINES)
def test_copy_button_covers_no_character_of_a_code_block(
    page: CdpPage, site_url: str, path: str
) -> None:
    _open(page, site_url + path)
    found = _run(page, COVERED)
    assert found["blocks"] > 0, f"{path} has no code block with a copy button"
    assert not found["covered"], f"{path}: the copy button hides text of {found['covered']}"


SEARCH = """(async () => {
  const input = document.querySelector('input.md-search__input');
  input.focus();
  const found = {};
  for (const query of QUERIES) {
    input.value = query;
    input.dispatchEvent(new Event('input', {bubbles: true}));
    input.dispatchEvent(new KeyboardEvent('keyup', {bubbles: true, key: 'Enter'}));
    let hits = [];
    for (let wait = 0; wait < 100 && !hits.length; wait++) {
      await new Promise(done => setTimeout(done, 100));
      hits = Array.from(document.querySelectorAll('.md-search-result__item > a'));
    }
    await new Promise(done => setTimeout(done, 300));  // the list fills in batches
    found[query] = Array.from(document.querySelectorAll('.md-search-result__item > a'))
      .map(a => new URL(a.href).pathname);
  }
  return found;
})()"""


def test_search_finds_pages_by_the_parts_of_topic_and_field_names(
    page: CdpPage, site_url: str
) -> None:
    _open(page, site_url)
    queries = {"estop": "/ros-interfaces/", "release_estop": "/tutorials/deploy-sim/"}
    found = _run(page, f"const QUERIES = {json.dumps(list(queries))};\n{SEARCH}")
    for query, expected in queries.items():
        assert expected in found[query], f"searching {query!r} finds {found[query]}"
