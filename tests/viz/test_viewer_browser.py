"""The HTML report in a real browser: headless Chromium with the network off opens the
file, draws the 3D scene, and redraws it when the step slider is moved.

Driven through Chromium's DevTools protocol (``--remote-debugging-port``) with the
``websocket-client`` package; skipped when Chromium or that package is missing.
"""

from __future__ import annotations

import base64
import io
import itertools
import json
import shutil
import socket
import subprocess
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from assemblykit.io.assembly import load_assembly
from assemblykit.planning.sequence import Plan, Step
from assemblykit.viz.viewer import write_report

pytestmark = pytest.mark.browser

websocket = pytest.importorskip("websocket", reason="websocket-client is not installed")
Image = pytest.importorskip("PIL.Image", reason="Pillow is not installed")
CHROMIUM = next(
    (shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)),
    None,
)
if CHROMIUM is None:
    pytest.skip("Chromium is not installed", allow_module_level=True)

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=1100,1000",
]
DEADLINE = 20.0


class DevTools:
    """A minimal DevTools-protocol client over one page's websocket."""

    def __init__(self, url: str) -> None:
        self.socket = websocket.create_connection(url, timeout=DEADLINE)
        self.ids = itertools.count(1)

    def send(self, method: str, **params: Any) -> dict[str, Any]:
        number = next(self.ids)
        self.socket.send(json.dumps({"id": number, "method": method, "params": params}))
        while True:
            message = json.loads(self.socket.recv())
            if message.get("id") == number:
                assert "error" not in message, message
                return message.get("result", {})

    def evaluate(self, expression: str) -> Any:
        result = self.send("Runtime.evaluate", expression=expression, returnByValue=True)
        return result["result"].get("value")

    def wait_for(self, expression: str) -> Any:
        end = time.monotonic() + DEADLINE
        while time.monotonic() < end:
            value = self.evaluate(expression)
            if value:
                return value
            time.sleep(0.1)
        raise AssertionError(f"timed out waiting for {expression}")

    def screenshot(self, clip: dict[str, float]) -> np.ndarray:
        data = self.send("Page.captureScreenshot", format="png", clip={**clip, "scale": 1})
        image = Image.open(io.BytesIO(base64.b64decode(data["data"]))).convert("RGB")
        return np.asarray(image, dtype=np.int16)


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.fixture
def browser(tmp_path: Path) -> Iterator[DevTools]:
    port = free_port()
    process = subprocess.Popen(
        [
            CHROMIUM,
            *FLAGS,
            f"--remote-debugging-port={port}",
            f"--user-data-dir={tmp_path / 'profile'}",
            "about:blank",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        end = time.monotonic() + DEADLINE
        pages: list[dict[str, Any]] = []
        while not pages:
            if time.monotonic() > end:
                raise AssertionError("Chromium did not open its DevTools port")
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list") as reply:
                    pages = [t for t in json.load(reply) if t["type"] == "page"]
            except OSError:
                time.sleep(0.1)
        tools = DevTools(pages[0]["webSocketDebuggerUrl"])
        tools.send("Network.enable")
        tools.send(
            "Network.emulateNetworkConditions",
            offline=True,
            latency=0,
            downloadThroughput=-1,
            uploadThroughput=-1,
        )
        yield tools
        tools.socket.close()
    finally:
        process.terminate()
        process.wait(timeout=10)


@pytest.fixture
def report(tmp_path: Path) -> Path:
    assembly = load_assembly(DEMO)
    lifted = ("cover", "pin_1", "pin_2", "pin_3", "pin_4")
    steps = (
        Step(lifted, np.array([0.0, 0.0, 1.0]), ("base", "housing"), ()),
        Step(("plug",), np.array([1.0, 0.0, 0.0]), ("base", "housing"), ()),
    )
    plan = Plan(tuple(assembly.names), steps, (), None, 2)
    return write_report(assembly, plan, tmp_path / "report.html")


def test_report_draws_offline_and_the_slider_changes_the_view(browser: DevTools, report: Path):
    browser.send("Page.enable")
    browser.send("Page.navigate", url=report.as_uri())
    browser.wait_for(
        "typeof Plotly !== 'undefined' && !!document.querySelector('#assembly-view canvas')"
        " && document.getElementById('assembly-view')._fullLayout !== undefined"
    )
    scene = browser.evaluate(
        "(() => { const r = document.querySelector('#assembly-view canvas')"
        ".getBoundingClientRect(); return {x: r.x, y: r.y, width: r.width, height: r.height}; })()"
    )
    assert scene["width"] > 100 and scene["height"] > 100
    time.sleep(1.0)  # let WebGL finish the first frame
    before = browser.screenshot(scene)
    # drawn: the parts' colours cover a good share of the scene, not a blank canvas
    painted = np.any(np.abs(before - before[0, 0]) > 30, axis=2).mean()
    assert painted > 0.05

    rail = browser.evaluate(
        "(() => { const r = document.querySelector('#assembly-view .slider-rail-touch-rect')"
        ".getBoundingClientRect(); return {x: r.x, y: r.y, width: r.width, height: r.height}; })()"
    )
    x, y = rail["x"] + rail["width"] - 3, rail["y"] + rail["height"] / 2
    for kind in ("mousePressed", "mouseReleased"):
        browser.send("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)
    assert browser.wait_for(
        "document.getElementById('assembly-view')._fullLayout.sliders[0].active === 2"
    )
    time.sleep(1.0)
    after = browser.screenshot(scene)
    changed = np.any(np.abs(after - before) > 30, axis=2).mean()
    assert changed > 0.01
