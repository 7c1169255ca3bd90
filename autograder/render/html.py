"""The HTML report: a self-contained page in the student's language, with pictures.

Built from the results model alone: the robot's path over the world (collisions marked),
message-interval plots for rate tests, each test's feedback as the student may see it,
and, once, the whole output of the student's programs as the sandbox kept it (the tail of
the node's log when only that is known).  Urdu pages are right to left, like the quiz
pages.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from markupsafe import Markup

from autograder.core.results import RunResult, number
from autograder.i18n import is_rtl
from autograder.quiz.localize import Text, format_percent, using_language
from autograder.quiz.render import environment
from autograder.render import OutputFormat
from autograder.render.charts import intervals_svg


def _trajectories(result: RunResult, exercise_folder: Path | None) -> list[dict[str, Any]]:
    from sim.recorder import Recording
    from sim.svg import trajectory_svg
    from sim.worldfile import load_world, title_of

    pictures = []
    for module, recorded in result.data.get("recordings", {}).items():
        try:
            recording = Recording.from_dict(recorded)
            local = exercise_folder / f"{recording.world}.yaml" if exercise_folder else None
            spec = load_world(local if local and local.exists() else recording.world)
        except Exception:  # noqa: BLE001 - a picture we cannot draw is left out
            continue
        if not recording.samples or recording.distance() < 0.05:
            continue  # the robot stood still: nothing to look at
        title = title_of(spec)  # in English when not translated: marked so
        english = result.lang != "en" and title in (spec.title, spec.name)
        pictures.append({"module": module,
                         "world": Text(title, "en" if english else result.lang, english),
                         "collisions": len(recording.collisions),
                         "svg": Markup(trajectory_svg(spec, recording, spec.goal))})
    return pictures


def to_html(result: RunResult, exercise_folder: Path | None = None) -> str:
    lang = result.lang
    tests = []
    for test in result.tests:
        tests.append({
            "test": test,
            "label": Text(test.label, lang),
            "message": Text(test.student_message, lang) if test.student_message else None,
            "hint": Text(test.student_hint, lang) if test.student_hint else None,
            "charts": [intervals_svg([tuple(p) for p in chart["points"]], chart.get("limit"),
                                     chart["title"])
                       for chart in test.data.get("charts", [])],
            "score": number(test.score), "max_score": number(test.max_score),
        })
    with using_language(lang):
        return _render(result, tests, exercise_folder)


def _render(result: RunResult, tests: list[dict[str, Any]], exercise_folder: Path | None) -> str:
    lang = result.lang
    return environment().get_template("report.html").render(
        lang=lang, dir="rtl" if is_rtl(lang) else "ltr", result=result,
        title=Text(result.title, lang), tests=tests,
        score=number(result.score), max_score=number(result.max_score),
        percent=format_percent(result.fraction, lang),
        pass_mark=format_percent(result.pass_mark, lang),
        pictures=_trajectories(result, exercise_folder))


FORMAT = OutputFormat(
    "html", "Write a self-contained HTML report to this file.", to_html,
    batch_file="report.html", order=20)
