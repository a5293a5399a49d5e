"""The HTML report in a real browser: headless Chromium with the network off opens the
file, draws the assembled model large in the colours of its part list, highlights the
parts of the shown step (every other part one grey) with an arrow that starts on them,
along the step's direction, and plays the steps; the same on the 184-block crossvault
(bundled) and the 527-block dome (when ``$ASSEMBLYKIT_DATA`` holds it), whose reports are
written in under 25 MB. Colours are measured on screenshots: by hue where the
view is shaded, exactly where the test switches the shading off.

All of them run in the slow tier (``python -m pytest -m slow``), which CI runs with
Chromium installed. Driven through Chromium's DevTools protocol
(``--remote-debugging-port``) with the ``websocket-client`` package. Without Chromium or
that package a test is skipped, or fails under CI (``$CI`` set and not empty), where
these tests must run.
"""

from __future__ import annotations

import base64
import importlib
import io
import itertools
import json
import os
import shutil
import subprocess
import time
import urllib.request
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from types import ModuleType
from typing import Any, NoReturn, TypeVar

import numpy as np
import pytest
import trimesh
from PIL import Image

from assemblykit.io.assembly import load_assembly
from assemblykit.model.assembly import Assembly
from assemblykit.planning.sequence import Plan, Step
from assemblykit.viz.viewer import ARROW_FRACTION, DIM_COLOR, PALETTE, write_report
from datasets import dataset

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "src" / "assemblykit" / "examples" / "gearbox_demo" / "gearbox.yaml"
BROWSERS = ("chromium", "chromium-browser", "google-chrome")
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--remote-allow-origins=*",
    "--remote-debugging-port=0",
    "--window-size=1100,1000",
]
DEADLINE = 30.0
"""Seconds to wait for the browser, the page or the drawing before failing."""
POLL = 0.1
UP = np.array([0.0, 0.0, 1.0])
ON_THE_PARTS = 1e-3
"""Largest distance, as a fraction of the assembly's size, from the back of a step's arrow
to the nearest moved part (the page rounds the arrow's vertices)."""
LIFTED = ("cover", "pin_1", "pin_2", "pin_3", "pin_4")

T = TypeVar("T")


def until(probe: Callable[[], T], what: str, accept: Callable[[T], bool] = bool) -> T:
    """The first value of ``probe`` that ``accept`` takes, asking every ``POLL`` seconds for
    ``DEADLINE`` seconds at most."""
    end = time.monotonic() + DEADLINE
    while True:
        value = probe()
        if accept(value):
            return value
        if time.monotonic() > end:
            raise AssertionError(f"timed out after {DEADLINE:.0f} s waiting for {what}")
        time.sleep(POLL)


def missing(what: str) -> NoReturn:
    """Skip the calling test for want of ``what``; under CI, where the browser tests must
    run, fail it."""
    if os.environ.get("CI"):
        pytest.fail(
            f"{what}; the browser tests must run under CI (CI={os.environ['CI']!r})",
            pytrace=False,
        )
    pytest.skip(what)


def find_chromium() -> str:
    """The first of ``BROWSERS`` on ``PATH``."""
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    missing(f"Chromium is not installed: none of {', '.join(BROWSERS)} is on PATH")


def import_websocket() -> ModuleType:
    """The ``websocket-client`` package."""
    try:
        return importlib.import_module("websocket")
    except ImportError:
        missing("websocket-client is not installed")


def painted(image: np.ndarray) -> np.ndarray:
    """Where ``image`` differs from its background (the colour near its corner)."""
    return np.any(np.abs(image - image[2, 2]) > 30, axis=2)


class DevTools:
    """A minimal DevTools-protocol client over one page's websocket."""

    def __init__(self, socket: Any) -> None:
        self.socket = socket
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
        """The first true value of the JavaScript ``expression``."""
        return until(lambda: self.evaluate(expression), expression)

    def open(self, page: Path) -> dict[str, float]:
        """Load ``page``, wait until plotly has set it up; the scene canvas's rectangle."""
        self.send("Page.enable")
        self.send("Page.navigate", url=page.as_uri())
        self.wait_for(
            "typeof Plotly !== 'undefined' && !!document.querySelector('#assembly-view canvas')"
            " && document.getElementById('assembly-view').dataset.step === '0'"
        )
        return self.evaluate(
            "(() => { const r = document.querySelector('#assembly-view canvas')"
            ".getBoundingClientRect(); return {x: r.x, y: r.y, width: r.width,"
            " height: r.height}; })()"
        )

    def screenshot(self, clip: dict[str, float]) -> np.ndarray:
        data = self.send("Page.captureScreenshot", format="png", clip={**clip, "scale": 1})
        image = Image.open(io.BytesIO(base64.b64decode(data["data"]))).convert("RGB")
        return np.asarray(image, dtype=np.int16)

    def drawn(self, clip: dict[str, float]) -> np.ndarray:
        """The area ``clip`` once WebGL has drawn into it: a screenshot with something
        painted, the same as the one before it."""
        last = self.screenshot(clip)

        def still() -> bool:
            nonlocal last
            before, last = last, self.screenshot(clip)
            return bool(painted(last).any()) and np.array_equal(before, last)

        until(still, "the scene drawn and still")
        return last


class Chromium:
    """Headless Chromium with the network off, shared by the module's tests and started by
    the first one that asks for it, once that test has what it shows: a test skipped for
    want of data neither waits for the browser nor fails for it."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.process: subprocess.Popen[bytes] | None = None
        self.tools: DevTools | None = None

    def devtools(self) -> DevTools:
        """The client of the browser's page; Chromium starts on the first call."""
        binary = find_chromium()
        websocket = import_websocket()
        if self.tools is None:
            if self.process is not None:
                pytest.fail("Chromium did not start for an earlier test", pytrace=False)
            self.tools = self.start(binary, websocket)
        return self.tools

    def start(self, binary: str, websocket: ModuleType) -> DevTools:
        profile = self.folder / "profile"
        log = self.folder / "chromium.log"
        with log.open("wb") as stderr:
            self.process = subprocess.Popen(
                [binary, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
                stdout=subprocess.DEVNULL,
                stderr=stderr,
            )
        pages = until(lambda: self.pages(profile, log), "Chromium's DevTools endpoint")
        tools = DevTools(
            websocket.create_connection(pages[0]["webSocketDebuggerUrl"], timeout=DEADLINE)
        )
        tools.send("Network.enable")
        tools.send(
            "Network.emulateNetworkConditions",
            offline=True,
            latency=0,
            downloadThroughput=-1,
            uploadThroughput=-1,
        )
        return tools

    def pages(self, profile: Path, log: Path) -> list[dict[str, Any]]:
        """The browser's pages from its DevTools endpoint; none while that does not answer
        (the port is in ``DevToolsActivePort`` once it listens)."""
        assert self.process is not None
        if self.process.poll() is not None:
            raise AssertionError(
                f"Chromium exited with code {self.process.returncode}:\n{log.read_text()}"
            )
        active = profile / "DevToolsActivePort"
        lines = active.read_text().splitlines() if active.exists() else []
        if not lines or not lines[0].isdigit():
            return []
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{lines[0]}/json/list") as reply:
                return [t for t in json.load(reply) if t["type"] == "page"]
        except OSError:
            return []

    def close(self) -> None:
        if self.tools is not None:
            self.tools.socket.close()
        if self.process is not None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()


@pytest.fixture(scope="module")
def chromium(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Chromium]:
    browser = Chromium(tmp_path_factory.mktemp("chromium"))
    yield browser
    browser.close()


def painted_box(image: np.ndarray) -> tuple[float, float]:
    """Width and height of the drawn pixels' bounding box, as fractions of the image."""
    rows, cols = np.nonzero(painted(image))
    assert len(rows), "nothing drawn"
    return (
        (cols.max() - cols.min() + 1) / image.shape[1],
        (rows.max() - rows.min() + 1) / image.shape[0],
    )


def layered(assembly: Assembly, layers: int) -> Plan:
    """A plan lifting the parts in ``layers`` groups from the top down (for display)."""
    names = sorted(assembly.names, key=lambda n: -assembly.parts[n].mesh.bounds[1][2])
    groups = [tuple(g) for g in np.array_split(np.array(names, dtype=object), layers)]
    steps = tuple(
        Step(group, UP, tuple(n for later in groups[k + 1 :] for n in later), ())
        for k, group in enumerate(groups[:-1])
    )
    return Plan(tuple(assembly.names), steps, (), None, 1)


@pytest.fixture
def gearbox_report(tmp_path: Path) -> Path:
    assembly = load_assembly(DEMO)
    steps = (
        Step(LIFTED, UP, ("base", "housing"), (("housing", "cover"),)),
        Step(("plug",), np.array([1.0, 0.0, 0.0]), ("base", "housing"), ()),
    )
    plan = Plan(tuple(assembly.names), steps, (), None, 2)
    return write_report(assembly, plan, tmp_path / "report.html")


def show_step(browser: DevTools, number: int) -> dict[str, Any]:
    """Move the slider to step ``number``; what the page then draws: the face colours,
    the arrow trace, how far the step's parts moved and along which direction, the
    caption and the highlighted table rows."""
    browser.evaluate(
        "(() => { const s = document.getElementById('step-slider');"
        f" s.value = {number}; s.dispatchEvent(new Event('input')); }})()"
    )
    return browser.wait_for(
        "(() => { const gd = document.getElementById('assembly-view'),"
        " P = window.assemblyReport.data;"
        f" if (gd.dataset.step !== '{number}') return null;"
        " return {facecolor: Array.from(gd.data[0].facecolor), arrow: gd.data[1].visible,"
        " x: Array.from(gd.data[1].x), y: Array.from(gd.data[1].y),"
        " z: Array.from(gd.data[1].z),"
        f" moved: P.travel[{number}] - P.travel[{number - 1}],"
        f" direction: P.directions[{number - 1}],"
        " caption: document.getElementById('caption').textContent,"
        " current: Array.from(document.querySelectorAll('tr.current'), r => r.dataset.step)};"
        " })()"
    )


def show_step_one(browser: DevTools) -> dict[str, Any]:
    """:func:`show_step` 1."""
    return show_step(browser, 1)


def legend(browser: DevTools) -> dict[str, np.ndarray]:
    """The colour of each part in the report's part list, as the page draws it."""
    swatches = browser.evaluate(
        "Array.from(document.querySelectorAll('.swatch'), s =>"
        " [s.parentElement.textContent, getComputedStyle(s).backgroundColor])"
    )
    return {
        name: np.array([int(c) for c in color[color.index("(") + 1 : -1].split(",")[:3]])
        for name, color in swatches
    }


def arrow_gap(shown: dict[str, Any], assembly: Assembly, moved: Sequence[str]) -> float:
    """How far the back end of the shown arrow (the centre of its shaft's end) is from
    the nearest of the ``moved`` parts, where the step has moved them; as a fraction of
    the assembly's size."""
    arrow = np.column_stack([shown["x"], shown["y"], shown["z"]])
    d = np.asarray(shown["direction"], dtype=np.float64)
    heights = arrow @ d
    tail = arrow[heights < heights.min() + 1e-4 * assembly.scale].mean(axis=0)
    shift = d * shown["moved"]
    gaps = [
        trimesh.proximity.closest_point(
            assembly.parts[n].mesh.copy().apply_translation(shift), [tail]
        )[1][0]
        for n in moved
    ]
    return float(min(gaps)) / assembly.scale


def chromaticity(pixels: np.ndarray) -> np.ndarray:
    """Each colour's share of red, green and blue (what shading leaves of its hue)."""
    rgb = np.asarray(pixels, dtype=np.float64).reshape(-1, 3)
    return rgb / np.maximum(rgb.sum(axis=1, keepdims=True), 1)


NEUTRAL = 12
"""A pixel whose red, green and blue differ by at most this much is grey."""
HUE = 0.05
"""A shaded pixel shows a colour when their chromaticities differ by at most this much."""


def colored_pixels(image: np.ndarray) -> np.ndarray:
    """The painted pixels that are not grey (nor dark, where hues blur)."""
    spread = image.max(axis=2) - image.min(axis=2)
    return image[painted(image) & (spread > NEUTRAL) & (image.sum(axis=2) > 120)]


def showing(pixels: np.ndarray, color: np.ndarray) -> np.ndarray:
    """Which of ``pixels`` show ``color`` under the view's lighting."""
    return np.abs(chromaticity(pixels) - chromaticity(color)).max(axis=1) <= HUE


FLAT = (
    "Plotly.restyle(document.getElementById('assembly-view'), {lighting: {ambient: 1,"
    " diffuse: 0, specular: 0, fresnel: 0, roughness: 1}}, [0])"
)
"""Switch the parts' shading off: each pixel then shows its face's colour as it is."""
HIDE_AXES = "Plotly.restyle(document.getElementById('assembly-view'), {visible: false}, [2, 3])"
"""Hide the axis triad and its labels (their colours are not the parts')."""
EXACT = 3
"""A pixel drawn without shading shows a colour when no channel differs by more."""


def check_dimmed_grey(image: np.ndarray, colors: Sequence[np.ndarray]) -> None:
    """Every part but the step's drawn (without shading) in the one neutral grey: nearly
    all painted pixels are grey, and most of the others show one of ``colors`` (the
    moved parts'; the rest are their anti-aliased edges)."""
    coloured = colored_pixels(image)
    assert len(coloured) < 0.2 * painted(image).sum(), "the parts left are not grey"
    exact = np.zeros(len(coloured), dtype=bool)
    for color in colors:
        exact |= np.abs(coloured - color).max(axis=1) <= EXACT
    assert exact.mean() > 0.5, f"{exact.mean():.0%} of the coloured pixels in the step's colours"


def check_step_one(shown: dict[str, Any], assembly: Assembly, moved: Sequence[str]) -> None:
    """The parts ``moved`` in step 1 (along +z) in their own colours, every other part
    in the one neutral grey; a visible arrow along +z, ``ARROW_FRACTION`` of the
    assembly's diagonal long, starting on the moved parts, above them; the step's table
    row marked."""
    faces = np.cumsum([0] + [len(p.mesh.faces) for p in assembly])
    colors = np.asarray(shown["facecolor"])
    assert len(colors) == faces[-1]
    for index, name in enumerate(assembly.names):
        own = colors[faces[index] : faces[index + 1]]
        if name in moved:  # in its own colour
            assert np.all(own == PALETTE[index % len(PALETTE)]), name
        else:  # dimmed
            assert np.all(own == DIM_COLOR), name
    assert shown["arrow"] is True
    arrow = np.column_stack([shown["x"], shown["y"], shown["z"]])
    spread = arrow.max(axis=0) - arrow.min(axis=0)
    lo, hi = assembly.bounds
    assert spread[2] == pytest.approx(ARROW_FRACTION * np.linalg.norm(hi - lo), rel=1e-4)
    assert spread[2] > 2.5 * max(spread[0], spread[1])
    top = max(assembly.parts[n].mesh.bounds[1][2] for n in moved)
    assert arrow[:, 2].min() > top  # above the lifted parts
    assert arrow_gap(shown, assembly, moved) < ON_THE_PARTS  # starting on them
    assert shown["current"] == ["1"]


@pytest.mark.slow
@pytest.mark.early
def test_the_gearbox_fills_the_view_step_one_is_highlighted_and_play_walks_on(
    chromium: Chromium, gearbox_report: Path
) -> None:
    browser = chromium.devtools()
    scene = browser.open(gearbox_report)
    assert scene["width"] > 300 and scene["height"] > 300
    before = browser.drawn(scene)
    width, height = painted_box(before)
    assert width > 1 / 3 and height > 1 / 3  # the assembled state fills the view
    # the parts in the colours of the legend: the cover green, the housing red and the
    # base blue, each a good part of the picture (shaded, so compared by hue)
    colors, coloured = legend(browser), colored_pixels(before)
    for name in ("cover", "housing", "base"):
        assert showing(coloured, colors[name]).sum() > 0.15 * painted(before).sum(), name

    shown = show_step_one(browser)
    check_step_one(shown, load_assembly(DEMO), LIFTED)
    # the 120 x 80 x 60 box: an arrow 0.12 x its diagonal long
    spread = np.ptp(shown["z"])
    assert spread == pytest.approx(0.12 * np.sqrt(120**2 + 80**2 + 60**2), abs=1e-3)
    assert shown["caption"].startswith("Step 1 of 2: cover, pin_1, pin_2, pin_3 and 1 more")
    assert "+Z" in shown["caption"]
    until(
        lambda: np.any(np.abs(browser.screenshot(scene) - before) > 30, axis=2).mean() > 0.01,
        "step 1 drawn: over 1% of the scene's pixels changed",
    )

    browser.evaluate("document.getElementById('play').click()")
    assert browser.wait_for("document.getElementById('assembly-view').dataset.step === '2'")
    assert browser.evaluate("document.getElementById('caption').textContent").startswith(
        "Step 2 of 2: plug moves along +X"
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    "source",
    [
        "compas_assembly/crossvault_assembly.json",  # 184 blocks, bundled
        "compas_assembly/dome_assembly.json",  # 527 blocks, in $ASSEMBLYKIT_DATA
    ],
)
def test_a_large_report_is_small_large_on_screen_and_highlights_step_one(
    chromium: Chromium, tmp_path: Path, source: str
) -> None:
    assembly = load_assembly(dataset(source))
    plan = layered(assembly, 40)
    page = write_report(assembly, plan, tmp_path / "large.html")
    assert page.stat().st_size < 25_000_000
    browser = chromium.devtools()
    scene = browser.open(page)
    width, height = painted_box(browser.drawn(scene))
    assert width > 1 / 3 and height > 1 / 3
    legends = browser.evaluate("document.querySelectorAll('#assembly-view .legend').length")
    assert legends == 0
    # long lists are folded: 39 steps of hundreds of parts fit in a few screens
    assert browser.evaluate("document.body.scrollHeight") < 6000
    before = browser.drawn(scene)
    shown = show_step_one(browser)
    check_step_one(shown, assembly, plan.steps[0].parts)
    assert shown["caption"].startswith(f"Step 1 of {len(plan.steps)}: ")
    # the parts still assembled all in one grey: the moved ones the only colours (drawn
    # without shading, the axis triad hidden)
    browser.evaluate(FLAT)
    browser.evaluate(HIDE_AXES)
    until(
        lambda: np.any(np.abs(browser.screenshot(scene) - before) > 30, axis=2).mean() > 0.001,
        "step 1 drawn",
    )
    colors = legend(browser)
    check_dimmed_grey(browser.drawn(scene), [colors[n] for n in plan.steps[0].parts])
    # the last layer: blocks on the feet, far apart; the arrow starts on one of them,
    # not in the air between them
    last = plan.steps[-1].parts
    shown = show_step(browser, len(plan.steps))
    assert arrow_gap(shown, assembly, last) < ON_THE_PARTS
    centres = np.array([assembly.parts[n].mesh.bounds.mean(axis=0) for n in last])
    assert np.ptp(centres[:, :2], axis=0).max() > 0.3 * assembly.scale  # spread out


@pytest.mark.slow
def test_on_a_phone_the_report_fits_the_screen_and_still_shows_the_model(
    chromium: Chromium, gearbox_report: Path
) -> None:
    """A 390 x 844 phone screen: nothing runs off the side (no sideways scrolling), the
    3D view spans most of the width, and the assembled model fills a third of it."""
    browser = chromium.devtools()
    browser.send(
        "Emulation.setDeviceMetricsOverride",
        width=390,
        height=844,
        deviceScaleFactor=1,
        mobile=True,
    )
    try:
        scene = browser.open(gearbox_report)
        assert browser.evaluate("document.documentElement.scrollWidth") <= 390
        assert 300 <= scene["width"] <= 390 and scene["height"] > 250
        width, height = painted_box(browser.drawn(scene))
        assert width > 1 / 3 and height > 1 / 3
        check_step_one(show_step_one(browser), load_assembly(DEMO), LIFTED)
    finally:
        browser.send("Emulation.clearDeviceMetricsOverride")


@pytest.mark.slow
def test_every_part_is_drawn_in_the_colour_of_the_legend(chromium: Chromium, tmp_path: Path):
    """The demo gearbox taken apart one part per step, drawn without shading: in each
    step the only coloured pixels are the moved part's, in its colour in the part list
    (the commonest colour not grey is exactly that colour; the others are the part's
    anti-aliased edges)."""
    assembly = load_assembly(DEMO)
    order = [
        *LIFTED,
        *("shaft_a", "gear_a", "shaft_b", "gear_b", "spacer_a", "spacer_b"),
        *("plug", "housing", "base"),
    ]
    assert sorted(order) == sorted(assembly.names)
    x = np.array([1.0, 0.0, 0.0])
    steps = tuple(
        Step((name,), x if name in ("plug", "housing") else UP, tuple(order[k + 1 :]), ())
        for k, name in enumerate(order)
    )
    page = write_report(
        assembly, Plan(tuple(assembly.names), steps, (), None, 2), tmp_path / "r.html"
    )
    browser = chromium.devtools()
    scene = browser.open(page)
    browser.evaluate(FLAT)
    browser.evaluate(HIDE_AXES)
    colors = legend(browser)
    assert sorted(colors) == sorted(assembly.names)
    for number, name in enumerate(order, start=1):
        show_step(browser, number)
        until(
            lambda: len(colored_pixels(browser.screenshot(scene))) > 0,
            f"step {number} drawn",
        )
        coloured = colored_pixels(browser.drawn(scene))
        assert len(coloured) > 30, f"{name} not in view"
        values, counts = np.unique(coloured, axis=0, return_counts=True)
        assert np.abs(values[np.argmax(counts)] - colors[name]).max() <= EXACT, name
        exact = np.abs(coloured - colors[name]).max(axis=1) <= EXACT
        assert exact.mean() > 0.6, f"{name}: {exact.mean():.0%} of its pixels in its colour"
