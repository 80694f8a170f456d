"""report.html in a real browser, offline: headless Chromium driven over the Chrome DevTools
Protocol on a pipe (--remote-debugging-pipe: fds 3 and 4, NUL-terminated JSON; no extra Python
dependency), software GL (SwiftShader), every host name mapped to nothing.

For each template's report and for a page holding only the 3D view: the view draws (the
container's data-rendered="1" within 60 s), nothing is logged as an error and no exception
escapes, the page requests nothing but itself (data: and blob: URLs aside), the canvas holds a
picture (its pixels read back in the page are not one colour), each worst pose can be chosen and
redraws, and at a 400 px wide viewport the page does not scroll sideways.

Skips only when Chromium is absent and GEARCHECK_REQUIRE_BROWSER is not set (``make test`` sets
it, so CI fails instead of skipping). Run as a script to look at a page:
``python tests/test_browser.py page.html --width 400 --shot /tmp/page.png``.
"""

from __future__ import annotations

import base64
import contextlib
import fcntl
import json
import os
import queue
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import pytest

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")
RENDER_TIMEOUT_S = 60.0
PHONE_WIDTH = 400
TEMPLATES = ["eod_track_drive", "zhurong_differential", "nose_wheel_steering"]


def chromium_path() -> str | None:
    env = os.environ.get("GEARCHECK_CHROMIUM")
    if env:
        return env
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    return "/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None


class BrowserError(RuntimeError):
    pass


class Browser:
    """Headless Chromium over --remote-debugging-pipe: one page target, its events recorded."""

    def __init__(self, executable: str, width: int = 1100, height: int = 900, extra: tuple[str, ...] = ()):
        self._profile = tempfile.mkdtemp(prefix="gearcheck-chromium-")
        to_child_r, self._to_child = os.pipe()
        self._from_child, from_child_w = os.pipe()

        def wire() -> None:  # in the child: the pipe ends become fds 3 (commands in) and 4 (replies out)
            a = fcntl.fcntl(to_child_r, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_child_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        args = [executable, "--headless", "--no-sandbox", "--disable-gpu-sandbox", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--remote-debugging-pipe", f"--user-data-dir={self._profile}",
                "--host-resolver-rules=MAP * ~NOTFOUND", "--no-first-run", "--no-default-browser-check",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                "--disable-extensions", "--disable-default-apps", "--hide-scrollbars", "--mute-audio",
                f"--window-size={width},{height}", *extra, "about:blank"]
        self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL, pass_fds=(3, 4),
                                     preexec_fn=wire)  # noqa: PLW1509  (dup2 only; no lock is taken)
        os.close(to_child_r)
        os.close(from_child_w)
        self._next = 0
        self._replies: dict[int, dict] = {}
        self._events: queue.Queue = queue.Queue()
        self._cond = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self.events: list[dict] = []
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        for domain in ("Page", "Runtime", "Network", "Log"):
            self.call(f"{domain}.enable", session=True)

    def _read(self) -> None:
        buf = b""
        while True:
            try:
                chunk = os.read(self._from_child, 1 << 16)
            except OSError:
                chunk = b""
            if not chunk:
                with self._cond:
                    self._replies[-1] = {"error": {"message": "browser closed the pipe"}}
                    self._cond.notify_all()
                return
            buf += chunk
            while b"\0" in buf:
                raw, buf = buf.split(b"\0", 1)
                msg = json.loads(raw)
                if "id" in msg:
                    with self._cond:
                        self._replies[msg["id"]] = msg
                        self._cond.notify_all()
                else:
                    self._events.put(msg)

    def call(self, method: str, params: dict | None = None, session: bool = False, timeout: float = 60.0) -> dict:
        self._next += 1
        msg: dict = {"id": self._next, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = self.session
        os.write(self._to_child, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout
        with self._cond:
            while self._next not in self._replies and -1 not in self._replies:
                left = deadline - time.monotonic()
                if left <= 0:
                    raise BrowserError(f"{method}: no reply in {timeout} s")
                self._cond.wait(left)
            reply = self._replies.pop(self._next, None) or self._replies[-1]
        if "error" in reply:
            raise BrowserError(f"{method}: {reply['error']}")
        return reply.get("result", {})

    def drain(self) -> list[dict]:
        while True:
            try:
                self.events.append(self._events.get_nowait())
            except queue.Empty:
                return self.events

    def evaluate(self, expression: str, timeout: float = 60.0):
        result = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True},
                           session=True, timeout=timeout)
        if "exceptionDetails" in result:
            raise BrowserError(f"{expression[:60]}…: {result['exceptionDetails']}")
        return result["result"].get("value")

    def viewport(self, width: int, height: int = 900, mobile: bool = False) -> None:
        self.call("Emulation.setDeviceMetricsOverride", {"width": width, "height": height, "deviceScaleFactor": 1,
                                                         "mobile": mobile}, session=True)

    def open(self, url: str, wait_s: float = 30.0) -> None:
        self.events.clear()
        self.call("Page.navigate", {"url": url}, session=True)
        deadline = time.monotonic() + wait_s
        while time.monotonic() < deadline:
            if self.evaluate("document.readyState") == "complete":
                return
            time.sleep(0.05)
        raise BrowserError(f"{url}: not loaded in {wait_s} s")

    def wait_for(self, expression: str, timeout: float = RENDER_TIMEOUT_S) -> float:
        """Seconds until ``expression`` is truthy in the page."""
        t0 = time.monotonic()
        while time.monotonic() - t0 < timeout:
            if self.evaluate(expression):
                return time.monotonic() - t0
            time.sleep(0.1)
        raise BrowserError(f"not true within {timeout} s: {expression}")

    def screenshot(self, path: Path, full: bool = True) -> None:
        shot = self.call("Page.captureScreenshot", {"format": "png", "captureBeyondViewport": full}, session=True)
        Path(path).write_bytes(base64.b64decode(shot["data"]))

    def problems(self) -> list[str]:
        """Console errors, uncaught exceptions and error log entries since the page was opened."""
        out = []
        for e in self.drain():
            method, params = e.get("method"), e.get("params", {})
            if method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
                words = (str(a.get("value", a.get("description", ""))) for a in params["args"])
                out.append("console: " + " ".join(words))
            elif method == "Runtime.exceptionThrown":
                d = params["exceptionDetails"]
                out.append(f"exception: {d.get('text')} {d.get('exception', {}).get('description', '')}")
            elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
                out.append(f"log: {params['entry']['text']} {params['entry'].get('url', '')}")
        return out

    def requests(self) -> list[str]:
        return [e["params"]["request"]["url"] for e in self.drain() if e.get("method") == "Network.requestWillBeSent"]

    def close(self) -> None:
        with contextlib.suppress(BrowserError):
            self.call("Browser.close", timeout=10)
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._to_child)
        shutil.rmtree(self._profile, ignore_errors=True)


# --- what the page is asked ----------------------------------------------------------------------

RENDERED = "document.querySelector('.gc3d') && document.querySelector('.gc3d').dataset.rendered === '1'"

# pixel statistics of the 3D canvas, read back in the page (every 5th pixel)
CANVAS_STATS = """(() => {
  const c = document.querySelector('.gc3d canvas');
  const t = document.createElement('canvas'); t.width = c.width; t.height = c.height;
  const g = t.getContext('2d'); g.drawImage(c, 0, 0);
  const d = g.getImageData(0, 0, t.width, t.height).data;
  const seen = new Set(); let n = 0, s = 0, s2 = 0, bg = 0;
  const b = [d[0], d[1], d[2]];
  for (let i = 0; i < d.length; i += 20) {
    seen.add(d[i] | (d[i + 1] << 8) | (d[i + 2] << 16));
    const l = d[i] + d[i + 1] + d[i + 2]; s += l; s2 += l * l; n++;
    if (d[i] === b[0] && d[i + 1] === b[1] && d[i + 2] === b[2]) bg++;
  }
  return {width: t.width, height: t.height, colours: seen.size, std: Math.sqrt(Math.max(s2 / n - (s / n) ** 2, 0)),
          background: bg / n};
})()"""

WORST_VIEWS = "Array.from(document.querySelectorAll('.gc3d select option')).map(o => o.value)"

CHOOSE = """((value) => new Promise((done) => {
  const s = document.querySelector('.gc3d select'); s.value = value; s.dispatchEvent(new Event('change'));
  requestAnimationFrame(() => requestAnimationFrame(() => {
    const tag = document.querySelector('.gc3d-tag');
    const bar = document.querySelector('.gc3d-frames');
    done({status: document.querySelector('.gc3d-status').textContent, tag: tag.hidden ? null : tag.textContent,
          slider: bar.getBoundingClientRect().height > 0});
  }));
}))(%s)"""

# the motion slider moved to its middle frame: the status names that frame and the picture changes
SLIDE = """(() => new Promise((done) => {
  const slider = document.querySelector('.gc3d-frames input[type=range]');
  const before = document.querySelector('.gc3d canvas').toDataURL();
  slider.value = String(Math.floor(+slider.max / 2)); slider.dispatchEvent(new Event('input'));
  requestAnimationFrame(() => requestAnimationFrame(() => done({
    status: document.querySelector('.gc3d-status').textContent,
    output: document.querySelector('.gc3d-frames output').textContent,
    changed: document.querySelector('.gc3d canvas').toDataURL() !== before})));
}))()"""

PAGE_WIDTH = "Math.max(document.documentElement.scrollWidth, document.body.scrollWidth)"


def is_local(url: str, page: str) -> bool:
    return url == page or url.startswith(("data:", "blob:"))


PICTURE = "document.querySelector('.gc3d canvas').toDataURL()"
NEXT_FRAME = "new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(() => done(true))))"


def turn_zoom_reset(browser: Browser) -> dict:
    """Drag on the view (turns), shift-drag (pans), wheel (zooms), then Reset: each changes the
    picture and Reset brings back the first one, pixel for pixel."""
    browser.evaluate("document.querySelector('.gc3d-stage').scrollIntoView()")
    box = browser.evaluate("(() => { const r = document.querySelector('.gc3d canvas').getBoundingClientRect();"
                           " return [r.left + r.width / 2, r.top + r.height / 2]; })()")
    x, y = box
    first = browser.evaluate(PICTURE)
    changed = {}

    def mouse(kind: str, px: float, py: float, **extra) -> None:
        browser.call("Input.dispatchMouseEvent", {"type": kind, "x": px, "y": py, **extra}, session=True)

    before = first
    for name, modifiers in (("turn", 0), ("pan", 8)):  # 8: shift
        mouse("mousePressed", x, y, button="left", clickCount=1, modifiers=modifiers)
        for step in range(1, 6):
            mouse("mouseMoved", x + 24 * step, y + 8 * step, button="left", buttons=1, modifiers=modifiers)
        mouse("mouseReleased", x + 120, y + 40, button="left", clickCount=1, modifiers=modifiers)
        browser.evaluate(NEXT_FRAME)
        after = browser.evaluate(PICTURE)
        changed[name] = after != before
        before = after
    mouse("mouseWheel", x, y, deltaX=0, deltaY=-240)
    browser.evaluate(NEXT_FRAME)
    changed["zoom"] = browser.evaluate(PICTURE) != before
    browser.evaluate("document.querySelector('.gc3d-reset').click()")
    browser.evaluate(NEXT_FRAME)
    changed["reset_restores"] = browser.evaluate(PICTURE) == first
    assert all(changed.values()), f"the view's controls do not work: {changed}"
    return changed


def check_page(browser: Browser, page: Path, *, shots: Path | None = None) -> dict:
    """Open ``page`` at desktop width, then at 400 px: assert the offline 3D view works; returns
    what was measured."""
    url = page.resolve().as_uri()
    browser.viewport(1100, 900)
    browser.open(url)
    browser.wait_for(RENDERED)
    took = float(browser.evaluate("document.querySelector('.gc3d').dataset.renderMs")) / 1000.0
    stats = browser.evaluate(CANVAS_STATS)
    assert stats["width"] >= 300 and stats["height"] >= 200, stats
    assert stats["colours"] >= 20 and stats["std"] > 5.0, f"the 3D canvas looks blank: {stats}"
    assert 0.05 < stats["background"] < 0.98, f"the assembly fills none or all of the view: {stats}"
    controls = turn_zoom_reset(browser)
    views = browser.evaluate(WORST_VIEWS)
    shown = {}
    for value in views:
        shown[value] = browser.evaluate(CHOOSE % json.dumps(value))
        after = browser.evaluate(CANVAS_STATS)
        assert after["colours"] >= 20 and after["std"] > 5.0, f"{value}: blank canvas {after}"
        assert shown[value]["slider"] == (value == "frames"), f"{value}: the motion slider shows wrongly"
        if value.startswith("worst:"):
            assert shown[value]["tag"] and shown[value]["tag"].endswith(" mm"), shown[value]
        if value == "frames":
            slid = browser.evaluate(SLIDE)
            assert slid["changed"], f"moving the motion slider did not change the picture: {slid}"
            assert slid["output"] and slid["output"] in slid["status"], slid
            shown["frames_middle"] = slid
        if shots is not None:
            browser.evaluate("document.querySelector('.gc3d').scrollIntoView()")
            browser.screenshot(shots / f"{page.stem}_{value.replace(':', '_')}.png", full=False)
    problems = browser.problems()
    requests = browser.requests()
    assert not problems, problems
    network = [u for u in requests if not u.startswith(("file:", "data:", "blob:"))]
    assert not network, f"the page reaches for the network: {network}"
    beside = [u for u in requests if not is_local(u, url)]
    assert not beside, f"the page loads other files ({beside}): inline them (data: URLs) so report.html stands alone"

    browser.viewport(PHONE_WIDTH, 860, mobile=True)
    browser.open(url)
    browser.wait_for(RENDERED)
    width = browser.evaluate(PAGE_WIDTH)
    canvas = browser.evaluate("document.querySelector('.gc3d canvas').getBoundingClientRect().width")
    if shots is not None:
        browser.screenshot(shots / f"{page.stem}_phone_top.png", full=False)
        browser.evaluate("document.querySelector('.gc3d').scrollIntoView()")
        browser.screenshot(shots / f"{page.stem}_phone.png", full=False)
    assert width <= PHONE_WIDTH, f"the page scrolls sideways at {PHONE_WIDTH} px: {width} px wide"
    assert 0 < canvas <= PHONE_WIDTH
    assert not browser.problems()
    return {"render_s": took, "stats": stats, "views": shown, "phone_width": width, "controls": controls}


# --- tests ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def browser():
    exe = chromium_path()
    if exe is None:
        if os.environ.get("GEARCHECK_REQUIRE_BROWSER"):
            pytest.fail("GEARCHECK_REQUIRE_BROWSER is set but no Chromium was found (apt-get install chromium)")
        pytest.skip("Chromium is not installed (apt-get install chromium; GEARCHECK_REQUIRE_BROWSER=1 makes this fail)")
    b = Browser(exe)
    yield b
    b.close()


def test_viewer_page_works_offline(browser, tmp_path):
    """A page holding only the 3D view of a template's parts (no sweep needed), with one made-up
    worst pose measured on the exact B-rep."""
    from viewer_page import scene_page  # tests/viewer_page.py

    page = scene_page("nose_wheel_steering", tmp_path)
    measured = check_page(browser, page)
    assert set(measured["views"]) == {"built", "worst:0"}


def test_viewer_falls_back_to_text_without_webgl(tmp_path):
    """With WebGL switched off the view says so and lists the parts and worst poses instead."""
    exe = chromium_path()
    if exe is None:
        if os.environ.get("GEARCHECK_REQUIRE_BROWSER"):
            pytest.fail("GEARCHECK_REQUIRE_BROWSER is set but no Chromium was found")
        pytest.skip("Chromium is not installed")
    from viewer_page import scene_page

    page = scene_page("nose_wheel_steering", tmp_path)
    b = Browser(exe, extra=("--disable-3d-apis", "--disable-webgl"))
    try:
        b.open(page.resolve().as_uri())
        b.wait_for("document.querySelector('.gc3d').dataset.rendered === 'fallback'", timeout=30)
        shown = b.evaluate("""(() => {
          const f = document.querySelector('.gc3d-fallback');
          return {text: f.textContent, height: f.getBoundingClientRect().height,
                  stage: document.querySelector('.gc3d-stage').getBoundingClientRect().height};
        })()""")
        assert shown["height"] > 0 and shown["stage"] == 0, shown
        assert "3D view unavailable" in shown["text"] and "WebGL" in shown["text"]
        assert "pinion" in shown["text"] and "rack" in shown["text"] and " mm" in shown["text"]
        assert not b.problems()
    finally:
        b.close()


@pytest.mark.parametrize("name", TEMPLATES)
def test_report_works_offline(browser, template_check, name):
    report = template_check(name).folder / "report.html"
    assert 'class="gc3d"' in report.read_text(encoding="utf-8"), "report.html has no 3D view"
    measured = check_page(browser, report)
    worst = [v for v in measured["views"] if v.startswith("worst:")]
    assert worst, "the report's 3D view offers no worst pose"


def main(argv: list[str]) -> int:
    import argparse

    ap = argparse.ArgumentParser(description="open a page in headless Chromium (offline) and check its 3D view")
    ap.add_argument("page", type=Path)
    ap.add_argument("--shots", type=Path, help="folder for screenshots of each view and the phone width")
    args = ap.parse_args(argv)
    exe = chromium_path()
    if exe is None:
        raise SystemExit("no chromium")
    b = Browser(exe)
    try:
        if args.shots:
            args.shots.mkdir(parents=True, exist_ok=True)
        print(json.dumps(check_page(b, args.page, shots=args.shots), indent=1))
    finally:
        b.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
