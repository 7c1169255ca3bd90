"""Headless Chromium for tests: Debian's ``chromium`` driven by Playwright's Python package.

No browser is ever downloaded: Playwright gets Debian's executable.  Tests skip with a
clear reason when Chromium or the playwright package is absent.
"""

from __future__ import annotations

import base64
import contextlib
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

CHROMIUM_FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update",
                  "--disable-sync"]


def chromium_path() -> str | None:
    for candidate in (shutil.which("chromium"), "/usr/bin/chromium"):
        if candidate and Path(candidate).exists():
            return candidate
    return None


def skip_without_browser() -> str:
    """Chromium's path, or skip the test saying what to install."""
    path = chromium_path()
    if path is None:
        pytest.skip("Chromium is not installed: apt-get install chromium fonts-noto-core "
                    "(CI's .ci/run does this)")
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        pytest.skip("the playwright Python package is not installed: pip install playwright "
                    "(it drives Debian's Chromium; never run 'playwright install')")
    return path


class _Shared:
    """One headless Chromium for the whole test session, started at the first page:
    starting a browser costs more than most of the tests that use it. Each page gets a
    context of its own (its own storage, cookies and cache), as a fresh profile would."""

    playwright: Any = None
    browser: Any = None


def _browser(executable: str) -> Any:
    if _Shared.browser is None:
        from playwright.sync_api import sync_playwright

        _Shared.playwright = sync_playwright().start()
        _Shared.browser = _Shared.playwright.chromium.launch(
            executable_path=executable, headless=True, args=CHROMIUM_FLAGS)
    return _Shared.browser


def close_browser() -> None:
    """End the session's Chromium, if one was started (tests/conftest.py, at the end)."""
    if _Shared.playwright is not None:
        try:
            _Shared.browser.close()
        finally:
            _Shared.playwright.stop()
            _Shared.playwright = _Shared.browser = None


@contextlib.contextmanager
def chromium_page(width: int = 900, height: int = 1200) -> Iterator[Any]:
    """A page in a fresh context of the session's headless Chromium, closed afterwards."""
    context = _browser(skip_without_browser()).new_context(
        viewport={"width": width, "height": height}, locale="ur-PK")
    try:
        page = context.new_page()
        page.set_default_timeout(15_000)
        yield page
    finally:
        context.close()


_INK_JS = """
async ([data, box]) => {
  const img = new Image();
  img.src = "data:image/png;base64," + data;
  await img.decode();
  const canvas = document.createElement("canvas");
  canvas.width = img.width; canvas.height = img.height;
  const ctx = canvas.getContext("2d");
  ctx.drawImage(img, 0, 0);
  const [x0, y0, w, h] = box || [0, 0, img.width, img.height];
  const px = ctx.getImageData(x0, y0, w, h).data;
  let ink = 0, left = w, right = -1;
  for (let y = 0; y < h; y++) for (let x = 0; x < w; x++) {
    const i = (y * w + x) * 4;
    if (px[i] + px[i + 1] + px[i + 2] < 600) {
      ink++; left = Math.min(left, x); right = Math.max(right, x);
    }
  }
  return {ink, left, right, width: w, height: h};
}
"""


def ink(page: Any, png: bytes, box: tuple[int, int, int, int] | None = None) -> dict[str, int]:
    """Dark pixels in a screenshot (or a box of it), counted by the browser's own canvas."""
    data = base64.b64encode(png).decode()
    page.goto("about:blank")
    return page.evaluate(_INK_JS, [data, list(box) if box else None])


def fonts_used(page: Any, selector: str) -> list[dict[str, int]]:
    """For each element ``selector`` finds, the fonts Chromium drew its text with
    ({family: glyphs}), as its DevTools report them: what fell back to which font, which
    computed styles cannot tell."""
    cdp = page.context.new_cdp_session(page)
    try:
        cdp.send("DOM.enable")
        cdp.send("CSS.enable")
        root = cdp.send("DOM.getDocument", {"depth": -1})["root"]["nodeId"]
        nodes = cdp.send("DOM.querySelectorAll", {"nodeId": root, "selector": selector})
        found = []
        for node in nodes["nodeIds"]:
            fonts = cdp.send("CSS.getPlatformFontsForNode", {"nodeId": node})["fonts"]
            found.append({f["familyName"]: f["glyphCount"] for f in fonts})
        return found
    finally:
        cdp.detach()
