"""The HTML page in a real browser: headless Chromium loads it from a file with no console
error or uncaught exception, shows its figures, and sorts a table when a header is clicked.

Driven over the DevTools protocol (loopback only) with the ``websockets`` package; skipped
when Chromium (Debian: ``apt-get install chromium``) or websockets is missing.
"""

from __future__ import annotations

import contextlib
import json
import shutil
import subprocess
import tempfile
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

CHROMIUM = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome")
                 if shutil.which(n)), None)
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="no chromium (apt-get install chromium)")
TIMEOUT_S = 30.0


class Page:
    """One browser tab over the DevTools protocol; collects console errors and exceptions."""

    def __init__(self, socket: Any) -> None:
        self.socket = socket
        self.next_id = 0
        self.events: list[dict[str, Any]] = []

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline:
            message = json.loads(self.socket.recv(timeout=TIMEOUT_S))
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message.get("result", {})
            self.events.append(message)
        raise TimeoutError(method)

    def wait_for(self, event: str) -> None:
        deadline = time.monotonic() + TIMEOUT_S
        while not any(e.get("method") == event for e in self.events):
            if time.monotonic() > deadline:
                raise TimeoutError(event)
            self.events.append(json.loads(self.socket.recv(timeout=TIMEOUT_S)))

    def evaluate(self, expression: str) -> Any:
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        if "exceptionDetails" in result:
            raise RuntimeError(result["exceptionDetails"])
        return result["result"].get("value")

    def errors(self) -> list[str]:
        found = []
        for e in self.events:
            method, params = e.get("method"), e.get("params", {})
            if method == "Runtime.exceptionThrown":
                details = params["exceptionDetails"]
                found.append(details.get("exception", {}).get("description") or details["text"])
            elif method == "Runtime.consoleAPICalled" and params["type"] in ("error", "assert"):
                found.append(" ".join(str(a.get("value", a.get("description")))
                                      for a in params["args"]))
            elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
                found.append(params["entry"]["text"])
        return found


@pytest.fixture
def browser() -> Iterator[str]:
    """A headless Chromium on a loopback DevTools port; yields the port's base URL."""
    pytest.importorskip("websockets")
    profile = tempfile.mkdtemp(prefix="fsvla-chromium-")
    process = subprocess.Popen(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
         "--disable-extensions", "--remote-debugging-address=127.0.0.1",
         "--remote-debugging-port=0", f"--user-data-dir={profile}", "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        port_file = Path(profile) / "DevToolsActivePort"
        deadline = time.monotonic() + TIMEOUT_S
        while not (port_file.exists() and port_file.read_text().strip()):
            if process.poll() is not None or time.monotonic() > deadline:
                pytest.skip("chromium did not start its DevTools endpoint")
            time.sleep(0.1)
        yield f"http://127.0.0.1:{port_file.read_text().split()[0]}"
    finally:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=10)
        shutil.rmtree(profile, ignore_errors=True)


@contextlib.contextmanager
def load(base: str, path: Path) -> Iterator[Page]:
    """The browser's tab with ``path`` loaded, console and exceptions recorded."""
    from websockets.sync.client import connect

    with urllib.request.urlopen(f"{base}/json/list", timeout=TIMEOUT_S) as response:
        targets = json.load(response)
    target = next(t for t in targets if t["type"] == "page")
    with connect(target["webSocketDebuggerUrl"], max_size=None,
                 open_timeout=TIMEOUT_S) as socket:
        page = Page(socket)
        for domain in ("Runtime", "Log", "Page"):
            page.call(f"{domain}.enable")
        page.call("Page.navigate", url=path.resolve().as_uri())
        page.wait_for("Page.loadEventFired")
        yield page


def test_the_harness_sees_errors(browser: str, tmp_path: Path) -> None:
    bad = tmp_path / "bad.html"
    bad.write_text("<!DOCTYPE html><title>bad</title><script>console.error('boom');"
                   "undefinedFunction();</script>")
    with load(browser, bad) as page:
        page.call("Runtime.evaluate", expression="1")
        errors = page.errors()
    assert len(errors) == 2 and "boom" in errors[0] and "undefinedFunction" in errors[1]


def test_page_opens_without_console_errors(browser: str, written: Path) -> None:
    with load(browser, written / "report.html") as page:
        assert page.evaluate("document.title") == "fsvla safety report"
        images = page.evaluate(
            "Array.from(document.images).map(i => [i.complete, i.naturalWidth])")
        assert len(images) == 3 and all(done and width > 100 for done, width in images)
        # Sorting: click SSR of the aggregate table twice (ascending, then descending).
        order = page.evaluate("""(() => {
            const table = document.getElementById('t-aggregate');
            const heads = Array.from(table.tHead.rows[table.tHead.rows.length - 1].cells);
            const th = heads.find(c => c.textContent.trim().startsWith('SSR'));
            const names = () => Array.from(table.tBodies[0].rows, r => r.cells[0].textContent);
            th.click(); const up = names(); th.click(); const down = names();
            return [up, down, th.getAttribute('aria-sort')];
        })()""")
        assert order == [["a_b & c%", "beta"], ["beta", "a_b & c%"], "descending"]
        # A table with section rows and missing values sorts too (sections hidden).
        hidden = page.evaluate("""(() => {
            const table = document.getElementById('t-per_category');
            table.tHead.rows[1].cells[1].click();
            const section = table.querySelector('tr.section');
            return getComputedStyle(section).display;
        })()""")
        assert hidden == "none"
        time.sleep(0.2)
        page.call("Runtime.evaluate", expression="1")  # drain events that came meanwhile
        assert page.errors() == []
