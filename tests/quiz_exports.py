"""What the LMS export tests share (tests/quiz/export/ and tests/quiz/test_export.py): the
course's quiz files, a quiz of edge cases, and how a quiz string reads once shown."""

from __future__ import annotations

import itertools
from collections.abc import Iterator
from pathlib import Path

from autograder.i18n.text import CODE_SPAN, Text
from autograder.quiz.catalog import load_all

REPO = Path(__file__).resolve().parents[1]
FILES = load_all(REPO)

EDGE = """\
id: 9-edge
title: "Edge: `<tags>` & more"
pass_mark: 0.6
questions:
  - id: with-code
    type: single
    text: "What does `x < 2` give?"
    code: |
      if x < 2 and y > 1:
          print("]]>")
    options:
      - {id: 1st, text: The first}
      - {id: other, text: Another}
      - {id: none, text: None of these, pin: true}
    answer: 1st
    points: 2
  - id: four-right
    type: multiple
    partial_credit: true
    text: Pick the even numbers.
    options: [{id: a, text: "2"}, {id: b, text: "4"}, {id: c, text: "6"}, {id: d, text: "8"},
              {id: e, text: "9"}]
    answer: [a, b, c, d]
  - id: ratio
    type: numeric
    text: What is 1/3, to two places?
    answer: 0.33
    tolerance: 0.005
"""




def expected(text: Text) -> str:
    """The text of a quiz string as shown: code without backticks, spaces collapsed."""
    return " ".join(CODE_SPAN.sub(r"\1", text.value).split())


def subsets(ids: list[str]) -> Iterator[list[str]]:
    for n in range(len(ids) + 1):
        yield from (list(c) for c in itertools.combinations(ids, n))

