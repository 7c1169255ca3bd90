"""The pictures of the world carry a legend and a scale bar (sim/legend.py), in the
report's replay and in `sim run --svg`, in English and Urdu; the report's caption counts
the collisions in words."""

from __future__ import annotations

import dataclasses
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from fractions import Fraction

import pytest

from autograder.core.results import RunResult, TestResult
from autograder.i18n import set_language
from autograder.render.html import to_html
from sim.recorder import Command, Contact, Recording, Sample
from sim.svg import scene_svg, trajectory_svg
from sim.worldfile import load_world

SVG = "{http://www.w3.org/2000/svg}"


@pytest.fixture(autouse=True)
def _english() -> Iterator[None]:
    set_language("en")
    yield
    set_language("en")


def _recording(collisions: int = 1) -> Recording:
    samples = [Sample(t * 0.1, 3 + 0.05 * t, 3.0, 0.0, 0.5, 0.0) for t in range(30)]
    hits = [Contact(1.0 + i, 4.2, 3.0, "box 0") for i in range(collisions)]
    # Its command makes it a run the report replays, as every run of a node's is.
    return Recording(world="obstacles", samples=samples, collisions=hits,
                     commands=[Command(0.0, 0.5, 0.0)])


def _legend(svg: str) -> tuple[ET.Element, list[str]]:
    root = ET.fromstring(svg)
    legend = next(g for g in root.iter(f"{SVG}g") if g.get("class") == "legend")
    return legend, [t.text or "" for t in legend.iter(f"{SVG}text")]


def _placed(legend: ET.Element) -> tuple[float, float, float]:
    """Where the legend group is drawn: its left, its top, and its zoom."""
    found = re.fullmatch(r"translate\(([-\d.]+) ([-\d.]+)\) scale\(([\d.]+)\)",
                         legend.get("transform", ""))
    assert found is not None
    left, top, zoom = (float(v) for v in found.groups())
    return left, top, zoom


def test_the_svg_of_a_run_has_a_legend_and_a_scale_bar() -> None:
    spec = load_world("obstacles")
    svg = trajectory_svg(spec, _recording())
    legend, labels = _legend(svg)
    assert labels == ["start", "goal", "path", "collision", "2 m"]
    scale = next(p for p in legend.iter(f"{SVG}path") if p.get("class") == "legend-scale")
    assert scale.get("data-metres") == "2"  # a third of a 6 m room at most
    x0, x1 = (float(v) for v in re.findall(r"M([-\d.]+),[-\d.]+ V", scale.get("d", "")))
    left, top, zoom = _placed(legend)
    assert (x1 - x0) * zoom == pytest.approx(2.0, abs=0.002)  # in the picture's metres
    # Below the arena: the viewBox grew to hold it, and the drawing is as before.
    viewbox = [float(v) for v in ET.fromstring(svg).get("viewBox", "").split()]
    texts_y = [top + zoom * float(t.get("y", "0")) for t in legend.iter(f"{SVG}text")]
    assert min(texts_y) > spec.size[1] + 0.1 and max(texts_y) < viewbox[1] + viewbox[3]
    assert svg.count('class="path"') == 1 and svg.count('class="collision"') == 1


def test_a_replayed_figure_of_several_runs_names_other_runs_and_the_robot() -> None:
    spec = load_world("obstacles")
    svg = scene_svg(spec, [_recording(), _recording(0)], spec.goal, '<g class="replay"/>')
    _legend_group, labels = _legend(svg)
    assert labels == ["start", "goal", "path", "other runs", "robot", "collision", "2 m"]


def test_the_legend_reads_right_to_left_in_urdu() -> None:
    set_language("ur")
    spec = load_world("obstacles")
    legend, labels = _legend(trajectory_svg(spec, _recording()))
    assert labels[:2] == ["آغاز", "منزل"] and labels[-2] == "ٹکراؤ"
    xs = [float(t.get("x", "0")) for t in legend.iter(f"{SVG}text")]
    assert xs[0] > xs[1] > xs[2]  # the first item on the right
    assert {t.get("text-anchor") for t in legend.iter(f"{SVG}text")} == {"end"}


def test_a_narrow_world_wraps_its_legend_into_rows() -> None:
    spec = dataclasses.replace(load_world("obstacles"), size=(2.0, 2.0))
    legend, _labels = _legend(trajectory_svg(spec, _recording()))
    rows = {t.get("y") for t in legend.iter(f"{SVG}text")}
    assert len(rows) > 1
    left, _top, zoom = _placed(legend)
    for text in legend.iter(f"{SVG}text"):  # every label starts inside the picture
        assert -0.1 <= left + zoom * float(text.get("x", "0")) <= spec.size[0] + 0.1


def test_the_legend_grows_with_a_wider_world_so_its_text_keeps_its_size() -> None:
    """A report shows every world at one width: a 6 m room's legend is zoomed by its
    width over 4.2 m, a 2 m room's not at all."""
    wide = _placed(_legend(trajectory_svg(load_world("obstacles"), _recording()))[0])[2]
    narrow_spec = dataclasses.replace(load_world("obstacles"), size=(2.0, 2.0))
    narrow = _placed(_legend(trajectory_svg(narrow_spec, _recording()))[0])[2]
    assert (wide, narrow) == (pytest.approx(6.1 / 4.2, abs=0.001), 1.0)  # 6.1: the margins


def _report(lang: str, collisions: int) -> str:
    test = TestResult(name="test_drives", label="Drives", score=Fraction(1),
                      max_score=Fraction(1), status="passed",
                      nodeid="test_a.py::test_drives")
    return to_html(RunResult("exercise", "error_handling", "Avoider", (test,), lang=lang,
                             recordings={"test_a.py": _recording(collisions)}))


def _caption(page: str) -> str:
    """The world figure's caption, up to the list of its tests."""
    found = re.search(r'<figure class="world">.*?<figcaption>(.*?)<span', page, re.DOTALL)
    assert found is not None
    return found.group(1)


@pytest.mark.parametrize(("collisions", "words"), [
    (0, "without a collision"), (1, "with 1 collision marked by a red cross"),
    (2, "with 2 collisions marked by red crosses")])
def test_the_caption_counts_collisions_in_words(collisions: int, words: str) -> None:
    caption = _caption(_report("en", collisions))
    assert words in caption and "the legend under the picture" in caption
    assert "marked with a cross (" not in caption


def test_the_caption_and_legend_are_in_urdu() -> None:
    set_language("ur")
    page = _report("ur", 1)
    assert "سرخ کراس" in _caption(page) and "collision" not in _caption(page)
    _group, labels = _legend(re.search(r"<svg.*?</svg>", page, re.DOTALL).group(0))
    assert labels == ["آغاز", "منزل", "راستہ", "روبوٹ", "ٹکراؤ", "2 m"]
