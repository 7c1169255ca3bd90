"""The Urdu HTML report in headless Chromium: right to left, Nastaliq unclipped, code LTR,
pictures drawn. The screenshot is kept in the test's tmp_path (report-ur.png) for a person
to look at: a fixed path in /tmp would belong to whichever user ran the tests first."""

from __future__ import annotations

import dataclasses
import math
from fractions import Fraction
from pathlib import Path

import pytest
from browser import chromium_page, fonts_used, ink

from autograder.core.results import IntervalChart, RunResult, TestResult
from autograder.render.html import to_html
from sim.recorder import Recording, Sample
from sim.worldfile import Fault


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
                   charts=(IntervalChart("cmd_vel", (*((0.1 * i, 0.1) for i in range(1, 30)),
                                                     (3.5, 0.6)), 0.15),)),
    )
    return RunResult("exercise", "timer_sync", "Timer synchronization: ایک multi-rate controller",
                     tests, lang="ur", log_tail="[INFO] [multi_rate_controller]: started",
                     recordings={"test_world.py": recording})


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
    recorded = dataclasses.replace(result.recordings["test_world.py"], world="practice_yard")
    result = dataclasses.replace(result, recordings={"test_world.py": recorded})
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


_REPLAY_JS = """
(figure) => {
  const f = document.querySelectorAll("figure.world")[figure];
  const robot = f.querySelector(".replay-robot");
  const scan = f.querySelector(".replay-scan").getAttribute("d");
  return {transform: robot.getAttribute("transform"),
          dots: (scan.match(/h0/g) || []).length, scan,
          shown: f.querySelector("g.replay").getAttribute("visibility"),
          controls: !f.querySelector(".replay-controls").hidden,
          clock: f.querySelector(".replay-clock").textContent,
          said: f.querySelector(".replay-said").textContent,
          max: Number(f.querySelector(".replay-time").max),
          faded: [...f.querySelectorAll('g.run[data-run="0"] .collision')].map(
            c => c.getAttribute("opacity")),
          dir: getComputedStyle(f.querySelector(".scene")).direction};
}
"""


def replay_result(lang: str = "en") -> RunResult:
    """A report of real simulated runs: two test modules in a room with a wall ahead (the
    first drives slowly straight into it, at about 9 s; the second's lidar goes silent at
    4 s), and one among obstacles."""
    from recorded_runs import a_test, recorded

    tests = (a_test("test_avoider.py", "test_drives", "The robot drives"),
             a_test("test_faulty_world.py", "test_no_collision", "No collision"),
             a_test("test_shutdown.py", "test_stops", "Stops on SIGINT"))
    return RunResult("exercise", "error_handling", "A robust obstacle avoider", tests,
                     lang=lang, recordings={
                         "test_avoider.py": recorded("wall_ahead", 12, linear=0.1, turn=0.0),
                         "test_faulty_world.py": recorded(
                             "wall_ahead", 8, turn=-0.6,
                             faults=(Fault(kind="dropout", start=4.0),)),
                         "test_shutdown.py": recorded("obstacles", 12, turn=1.0)})


def test_replay_slider_moves_the_robot_its_scan_and_command(tmp_path: Path) -> None:
    page_file = tmp_path / "report.html"
    page_file.write_text(to_html(replay_result("ur")), encoding="utf-8")
    with chromium_page(width=900, height=1400) as page:
        problems: list[str] = []
        page.on("pageerror", lambda error: problems.append(str(error)))
        page.on("console", lambda message: problems.append(message.text)
                if message.type in ("error", "warning") else None)
        page.goto(page_file.as_uri())
        page.evaluate("document.fonts.ready")
        figure = page.locator("figure.world").first
        picture = figure.locator("svg.sim-trajectory")
        slider = figure.locator(".replay-time")
        at_start = page.evaluate(_REPLAY_JS, 0)
        before = picture.screenshot()
        slider.focus()
        page.keyboard.press("End")  # the end of the run
        at_end = page.evaluate(_REPLAY_JS, 0)
        after = picture.screenshot()
        box = slider.bounding_box()  # a click halfway along the slider
        page.mouse.click(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
        halfway = page.evaluate(_REPLAY_JS, 0)
        figure.screenshot(path=str(tmp_path / "replay.png"))
        figure.locator(".replay-run").select_option("1")  # the other run in this world
        other = page.evaluate(_REPLAY_JS, 0)
        slider.focus()
        page.keyboard.press("Home")
        play = figure.locator(".replay-play")
        labels = [play.text_content()]
        play.click()  # plays until the end of the run, or until paused
        labels.append(play.text_content())
        page.wait_for_function(
            "() => Number(document.querySelector('figure.world .replay-time').value) > 1")
        play.click()
        labels.append(play.text_content())
        played = page.evaluate(_REPLAY_JS, 0)
    assert problems == []  # the script ran under the page's policy, without errors
    assert at_start["controls"] and at_start["shown"] == "visible"
    assert at_start["dir"] == "ltr"  # the picture and its numbers, in an Urdu page
    assert at_start["clock"].startswith("0.00") and at_start["max"] == pytest.approx(12.0)
    assert at_start["transform"] == "translate(3.000 3.000) rotate(0.00)"
    assert at_start["dots"] == 0  # no scan before the first one
    # At the end: the robot elsewhere, a scan drawn from there, the command in force.
    assert at_end["clock"].startswith("12.00")
    assert at_end["transform"] != at_start["transform"]
    assert at_end["dots"] > 20 and at_end["said"] == "v 0.10 m/s, ω 0.00 rad/s"
    assert (at_start["faded"], at_end["faded"]) == (["0.25"], ["1"])  # into the wall
    assert before != after  # the picture itself changed
    # Halfway: another pose and another scan than at either end.
    assert 4.0 < float(halfway["clock"].split()[0]) < 8.0
    assert halfway["transform"] not in (at_start["transform"], at_end["transform"])
    assert halfway["scan"] not in ("", at_end["scan"])
    assert halfway["faded"] == ["0.25"]  # the wall is still ahead
    # The other run: its own length and pose at the same time.
    assert other["max"] == pytest.approx(8.0)
    assert other["transform"] != halfway["transform"]
    assert other["dots"] == 0  # its lidar was silent since 4 s: no stale scan is drawn
    # Play moves the time on by itself; the button says what a click will do.
    assert labels[0] == labels[2] != labels[1]
    assert float(played["clock"].split()[0]) > 1.0
