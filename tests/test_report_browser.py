"""The Urdu HTML report in headless Chromium: right to left, Nastaliq unclipped, code LTR,
pictures drawn. The screenshot is kept in the test's tmp_path (report-ur.png) for a person
to look at: a fixed path in /tmp would belong to whichever user ran the tests first."""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction
from pathlib import Path

from browser import chromium_page, fonts_used, ink

from autograder.core.results import RunResult, TestResult
from autograder.render.html import to_html
from sim.recorder import Recording, Sample


def urdu_result() -> RunResult:
    # A quarter circle through the empty room, as a recorded run would give.
    samples = [Sample(t=i * 0.1, x=3 + math.sin(i / 20), y=3 + 1 - math.cos(i / 20),
                      theta=i / 20, v=0.2, w=0.1) for i in range(32)]
    recording = Recording(world="empty_room", samples=samples, collisions=[])
    tests = (
        TestResult("test_node_starts", "node شروع ہوتا ہے اور `velocity_governor` کے نام سے "
                   "graph پر نظر آتا ہے", Fraction(1), Fraction(1), "passed"),
        TestResult("test_rate", "`cmd_vel` دس Hz پر رہتا ہے", Fraction(0), Fraction(2),
                   "failed", message="`cmd_vel` simulation time میں 3.1 Hz پر آیا؛ planner "
                   "کے چلتے ہوئے بھی control loop کو 10 Hz رکھنا ہے۔",
                   hint="کیا planner اپنے callback group میں ہے؟",
                   data={"charts": [{"kind": "intervals", "title": "cmd_vel",
                                     "points": [[0.1 * i, 0.1] for i in range(1, 30)]
                                     + [[3.5, 0.6]], "limit": 0.15}]}),
    )
    return RunResult("exercise", "timer_sync", "Timer synchronization: ایک multi-rate controller",
                     tests, lang="ur", log_tail="[INFO] [multi_rate_controller]: started",
                     data={"recordings": {"test_world.py": recording.to_dict()}})


_LAYOUT_JS = """
() => {
  const out = [];
  const selector = "h1, .test h3 span:not(.mark):not(.points), .message";
  for (const el of document.querySelectorAll(selector)) {
    const c = el.getBoundingClientRect();
    const r = document.createRange(); r.selectNodeContents(el);
    const t = r.getBoundingClientRect();
    out.push({ct: c.top, cb: c.bottom, cr: c.right, tt: t.top, tb: t.bottom, tr: t.right,
              overflow: el.scrollHeight - el.clientHeight});
  }
  const code = document.querySelector(".message code");
  return {items: out, direction: getComputedStyle(document.body).direction,
          font: getComputedStyle(document.body).fontFamily,
          nastaliq: document.fonts.check('20px "Noto Nastaliq Urdu"', "کیا"),
          code: getComputedStyle(code).direction,
          pictures: document.querySelectorAll("svg.sim-trajectory, svg.chart").length};
}
"""


def test_urdu_report_renders_rtl_in_nastaliq_unclipped(tmp_path: Path) -> None:
    page_file = tmp_path / "report.ur.html"
    page_file.write_text(to_html(urdu_result()), encoding="utf-8")
    with chromium_page() as page:
        page.goto(page_file.as_uri())
        page.evaluate("document.fonts.ready")
        layout = page.evaluate(_LAYOUT_JS)
        png = page.screenshot(full_page=True, path=str(tmp_path / "report-ur.png"))
        title = page.locator("h1").bounding_box()
        stats = ink(page, png)
        title_ink = ink(page, png, (0, int(title["y"]), 900, int(title["height"])))
    assert layout["direction"] == "rtl"
    assert layout["font"].startswith('"Noto Nastaliq Urdu"')
    assert layout["nastaliq"], "Noto Nastaliq Urdu is not available (fonts-noto-core)"
    assert layout["code"] == "ltr"
    assert layout["pictures"] == 2  # the robot's path and the interval plot
    for item in layout["items"]:
        assert item["tt"] >= item["ct"] - 1 and item["tb"] <= item["cb"] + 1, item
        assert item["overflow"] <= 0, item
    assert stats["ink"] > 10_000
    assert title_ink["right"] > 900 * 0.85  # the title starts on the right


_CAPTION_JS = """
() => {
  const caption = [...document.querySelectorAll("figcaption")].at(-1);  // the robot's path
  const world = caption.querySelector('[lang="en"]');
  const whole = document.createRange(); whole.selectNodeContents(caption);
  const c = whole.getBoundingClientRect(), w = world.getBoundingClientRect();
  const style = getComputedStyle(caption);
  return {direction: style.direction, align: style.textAlign,
          world: world.textContent, worldBidi: getComputedStyle(world).unicodeBidi,
          worldDirection: getComputedStyle(world).direction,
          textRight: c.right, textLeft: c.left, worldRight: w.right, worldLeft: w.left,
          chartFont: getComputedStyle(document.querySelector("svg.chart text")).fontFamily};
}
"""


def test_urdu_report_captions_read_right_to_left(tmp_path: Path) -> None:
    # A world beside the exercise whose title no catalog translates stays English: an
    # isolate inside the right-to-left caption, read first, so it stands on the right.
    (tmp_path / "practice_yard.yaml").write_text(
        "title: Practice yard, 6 x 6 m\nsize: [6.0, 6.0]\n", encoding="utf-8")
    result = urdu_result()
    recorded = {**result.data["recordings"]["test_world.py"], "world": "practice_yard"}
    result = dataclasses.replace(result, data={"recordings": {"test_world.py": recorded}})
    page_file = tmp_path / "report.ur.html"
    page_file.write_text(to_html(result, tmp_path), encoding="utf-8")
    with chromium_page() as page:
        page.goto(page_file.as_uri())
        page.evaluate("document.fonts.ready")
        found = page.evaluate(_CAPTION_JS)
        page.locator("figcaption").last.screenshot(path=str(tmp_path / "caption-ur.png"))
        runs = fonts_used(page, "bdi[lang=en], figcaption [lang=en]")
    assert (found["direction"], found["align"]) == ("rtl", "start"), found
    assert found["world"] == "Practice yard, 6 x 6 m"
    assert (found["worldBidi"], found["worldDirection"]) == ("isolate", "ltr")
    assert abs(found["worldRight"] - found["textRight"]) < 2, found
    assert found["worldLeft"] - found["textLeft"] > 100, found
    assert found["chartFont"].startswith('"Noto Sans"')
    assert runs and all(set(fonts) == {"Noto Sans"} for fonts in runs), runs
