"""The HTML report: a self-contained page in the student's language, with pictures.

Built from the results model alone: one picture per world with the robot's paths
(collisions marked) and a replay of each run (``replay.py``), message-interval plots for
rate tests, each test's feedback as the student may see it, and, once, the whole output
of the student's programs as the sandbox kept it (the tail of the node's log when only
that is known).  Urdu pages are right to left, like the quiz pages.  The page loads
nothing: its Content-Security-Policy allows no source but its own inline script, by hash.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from autograder.core.results import RunResult, number
from autograder.i18n import is_rtl
from autograder.i18n.templates import environment
from autograder.i18n.text import Text, format_percent, using_language
from autograder.render import OutputFormat, replay
from autograder.render.charts import intervals_svg
from autograder.render.verdict import core_heading, core_label


def to_html(result: RunResult, exercise_folder: Path | None = None) -> str:
    with using_language(lang := result.lang):
        return _render(result, _tests(result, lang), exercise_folder)


def _tests(result: RunResult, lang: str) -> list[dict[str, Any]]:
    """Each test as the template shows it (in the active language: a core test's mark)."""
    tests = []
    for test in result.tests:
        tests.append({
            "test": test,
            "label": Text(core_label(test), lang),
            "message": Text(test.student_message, lang) if test.student_message else None,
            "hint": Text(test.student_hint, lang) if test.student_hint else None,
            "charts": [{"svg": intervals_svg(list(chart.points), chart.limit, chart.title),
                        "limit": chart.limit is not None}
                       for chart in test.charts if chart.points],
            "score": number(test.score), "max_score": number(test.max_score),
        })
    return tests


def _render(result: RunResult, tests: list[dict[str, Any]], exercise_folder: Path | None) -> str:
    lang = result.lang
    pictures = replay.figures(result, exercise_folder)
    script, script_hash = replay.script()
    return environment().get_template("report.html").render(
        lang=lang, dir="rtl" if is_rtl(lang) else "ltr", result=result,
        title=Text(result.title, lang), tests=tests,
        score=number(result.score), max_score=number(result.max_score),
        percent=format_percent(result.fraction, lang),
        pass_mark=format_percent(result.pass_mark, lang),
        core_heading=core_heading(result),
        core_missed=[Text(t.label, lang) for t in result.core_missed],
        pictures=pictures,
        script=script if any(p.replay for p in pictures) else None, script_hash=script_hash)


FORMAT = OutputFormat(
    "html", "Write a self-contained HTML report to this file.", to_html,
    batch_file="report.html", order=20)
