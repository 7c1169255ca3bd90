"""The inline SVG of message intervals: the gaps as one line over simulation time, the
allowed gap as a dashed line with its value, each gap over it marked, the axes' ends
labelled; nothing for no points; the title escaped."""

from __future__ import annotations

import re
from xml.etree import ElementTree

from markupsafe import Markup

from autograder.render.charts import intervals_svg

SVG = "{http://www.w3.org/2000/svg}"


def _parse(svg: Markup) -> ElementTree.Element:
    return ElementTree.fromstring(str(svg))


def _path_points(root: ElementTree.Element) -> list[tuple[float, float]]:
    d = root.find(f"{SVG}path").get("d")
    return [(float(x), float(y)) for x, y in re.findall(r"[ML]([\d.]+),([\d.]+)", d)]


def test_no_points_no_picture():
    assert intervals_svg([], 0.1, "cmd_vel") == Markup("")


def test_the_gaps_the_limit_and_the_gaps_over_it():
    points = [(1.0, 0.1), (2.0, 0.1), (3.0, 0.4), (5.0, 0.1)]
    root = _parse(intervals_svg(points, 0.15, "cmd_vel <gaps>", width=560, height=180))
    assert (root.get("width"), root.get("height"), root.get("direction")) == ("560", "180",
                                                                             "ltr")
    assert root.find(f"{SVG}title").text == "cmd_vel <gaps>"  # escaped, read back whole
    drawn = _path_points(root)
    assert len(drawn) == 4
    # Time runs left to right across the plot (44 px left, 8 px right padding).
    assert drawn[0][0] == 44.0 and drawn[-1][0] == 552.0
    assert drawn[1][0] - drawn[0][0] == drawn[2][0] - drawn[1][0]
    # Gaps go up the picture: the long one is highest (smallest y), the equal ones level.
    assert drawn[2][1] < drawn[0][1] == drawn[1][1] == drawn[3][1]
    limit = root.find(f"{SVG}line[@class='limit']")
    assert drawn[2][1] < float(limit.get("y1")) < drawn[0][1]
    circles = root.findall(f"{SVG}circle")
    assert [(float(c.get("cx")), float(c.get("cy"))) for c in circles] == [drawn[2]]
    labels = [t.text for t in root.findall(f"{SVG}text")]
    assert "0.15 s" in labels  # the limit
    assert "0.46 s" in labels  # the top: the longest gap and a margin
    assert ["1.0 s", "5.0 s"] == labels[-2:]  # the time axis' ends


def test_without_a_limit_nothing_is_over_it_and_one_time_is_drawn():
    root = _parse(intervals_svg([(2.0, 0.3)], None, "odom"))
    assert root.find(f"{SVG}line[@class='limit']") is None
    assert root.findall(f"{SVG}circle") == []
    assert len(_path_points(root)) == 1
    labels = [t.text for t in root.findall(f"{SVG}text")]
    assert labels[-2:] == ["2.0 s", "3.0 s"]  # one time: a second's span


def test_a_gap_exactly_at_the_limit_is_not_over_it():
    root = _parse(intervals_svg([(1.0, 0.15), (2.0, 0.15 + 1e-12), (3.0, 0.2)], 0.15, "t"))
    assert len(root.findall(f"{SVG}circle")) == 1


def test_a_limit_above_every_gap_still_fits():
    root = _parse(intervals_svg([(1.0, 0.05), (2.0, 0.06)], 1.0, "t"))
    limit = float(root.find(f"{SVG}line[@class='limit']").get("y1"))
    assert 10 <= limit <= 180 - 24  # inside the plot
