"""Code in the Urdu report reads in its written order (issue 32): for each exercise, the
starter is checked in Urdu as a student would (``check --lang ur --html``, a run shared
with the modules that read the same output: tests/student_runs.py), and in headless
Chromium every code expression of its messages and hints (a code span, or Latin words
joined by operators, brackets or commas) has its characters laid out left to right, in
the order they are written.  A screenshot of each report is kept in the test's tmp_path
(report-<exercise>.png) for a person to look at."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from browser import chromium_page
from student_runs import Spec, StudentRuns, starter

from autograder.i18n.text import CODE_SPAN, ltr_runs

REPO = Path(__file__).resolve().parent.parent
EXERCISES = sorted(p.parent.name for p in (REPO / "assignments").glob("*/exercise.yaml"))

# Each occurrence of each expression in the tests' sections: the left edge of each of its
# characters that is not a space, line by line.  Characters of one line must stand left to
# right in their written order (a wrapped expression starts a new line).
_ORDER_JS = """
(expressions) => {
  const nodes = [], walker = document.createTreeWalker(
    document.querySelector("main") || document.body, NodeFilter.SHOW_TEXT);
  let text = "";
  while (walker.nextNode()) {
    const n = walker.currentNode;
    if (n.parentElement.closest("pre, script, style, svg")) continue;
    nodes.push([n, text.length]); text += n.data;
  }
  const at = (i) => {
    let k = nodes.length - 1;
    while (nodes[k][1] > i) k--;
    return [nodes[k][0], i - nodes[k][1]];
  };
  const out = [];
  for (const expr of expressions) {
    let from = 0, seen = 0;
    for (;;) {
      const i = text.indexOf(expr, from);
      if (i < 0) break;
      seen++; from = i + expr.length;
      const chars = [];
      for (let j = 0; j < expr.length; j++) {
        if (/\\s/.test(expr[j])) continue;
        const [node, off] = at(i + j);
        const r = document.createRange(); r.setStart(node, off); r.setEnd(node, off + 1);
        const box = r.getBoundingClientRect();
        chars.push({c: expr[j], x: box.left, y: Math.round(box.top)});
      }
      for (let j = 1; j < chars.length; j++) {
        if (chars[j].y === chars[j - 1].y && chars[j].x < chars[j - 1].x - 0.5) {
          out.push({expr, at: j, chars: chars.map(c => c.c + "@" + Math.round(c.x)).join(" ")});
          break;
        }
      }
    }
    if (!seen) out.push({expr, missing: true});
  }
  return out;
}
"""

# How the report once laid out an expression: each Latin piece its own isolate.
_SPLIT = ('<p class="planted" dir="rtl" lang="ur">جو reading شرط '
          '<bdi lang="en" dir="ltr">range_min</bdi> &lt;= <bdi lang="en" dir="ltr">r</bdi> '
          '&lt;= <bdi lang="en" dir="ltr">range_max</bdi> پوری نہ کرے</p>')


def expressions(text: str) -> set[str]:
    """The code of a message: its code spans, and its Latin runs that hold an operator,
    a bracket or a comma."""
    found = {m.group(1) for m in CODE_SPAN.finditer(text)}
    bare = CODE_SPAN.sub("\u0627", text)  # an Urdu letter stands for each span
    found |= {bare[a:b] for a, b in ltr_runs(bare) if re.search(r"[=<>(),\[\]+*/]", bare[a:b])
              and re.search(r"[A-Za-z]", bare[a:b])}
    return found


def test_expressions_are_found_in_a_message() -> None:
    text = ("جو reading شرط `range_min <= r <= range_max` پوری نہ کرے؛ cmd_vel پر "
            "linear.x=0.2, angular.z=0 آیا، اور (goal_x, goal_y) سے دور")
    assert expressions(text) == {"range_min <= r <= range_max", "linear.x=0.2, angular.z=0",
                                 "goal_x, goal_y"}


@pytest.mark.slow
@pytest.mark.parametrize("exercise", EXERCISES)
def test_every_code_expression_reads_in_written_order(exercise: str, tmp_path: Path,
                                                      student_runs: StudentRuns) -> None:
    [run] = student_runs.get(Spec("check", exercise, starter(exercise), "ur"))
    assert run.code == 0, run.stderr
    html, results = run.html, run.results
    exprs = set()
    for test in results["tests"]:
        for field in ("message", "hint", "label"):
            exprs |= expressions(test.get(field) or "")
    page_text = html.read_text(encoding="utf-8")
    with chromium_page() as page:
        page.goto(html.as_uri())
        page.evaluate("document.fonts.ready")
        # The check sees a split expression: planted as the report once laid it out.
        page.evaluate("(html) => (document.querySelector('main') || document.body)"
                      ".insertAdjacentHTML('beforeend', html)", _SPLIT)
        planted = page.evaluate(_ORDER_JS, ["range_min <= r <= range_max"])
        page.evaluate("document.querySelector('.planted').remove()")
        found = page.evaluate(_ORDER_JS, sorted(exprs))
        page.screenshot(path=str(tmp_path / f"report-{exercise}.png"), full_page=True)
    assert planted and not planted[0].get("missing"), planted
    assert [f for f in found if not f.get("missing")] == [], found
    # What the page does not show as text (a test that reveals nothing) is not counted;
    # every expression of a message it shows is on the page.
    assert exprs, f"the starter of {exercise} fails with no code in its feedback"
    assert 'dir="rtl"' in page_text
