"""Per-attempt option order (autograder.quiz.shuffle): a seed gives one order, the same in
every run, and pinned options keep their places."""

from __future__ import annotations

import random

from quiz_course import QUIZ_COURSE

from autograder.quiz.model import Option, load_quiz
from autograder.quiz.shuffle import attempt_rng, option_order, shuffle_unpinned

PART2 = load_quiz(QUIZ_COURSE / "quizzes" / "part2-rclpy.yaml").quiz


def test_a_seed_gives_the_same_order_in_every_run() -> None:
    q = PART2.questions[0]
    first = attempt_rng("student-7", PART2, q).random()
    assert attempt_rng("student-7", PART2, q).random() == first
    # Stable across processes and Python versions: a string seed is hashed with SHA-512.
    assert first == random.Random(f"student-7:{PART2.id}:{q.id}").random()
    assert attempt_rng("student-8", PART2, q).random() != first


def test_pinned_options_keep_their_places() -> None:
    options = tuple(Option(id=c, text=c.upper(), pin=c in "ae") for c in "abcde")
    seen = set()
    for seed in range(50):
        order = shuffle_unpinned(options, random.Random(seed))
        assert (order[0].id, order[4].id) == ("a", "e")
        assert sorted(o.id for o in order) == list("abcde")
        seen.add(tuple(o.id for o in order))
    assert len(seen) == 6  # every order of b, c, d turns up


def test_without_a_seed_the_files_order() -> None:
    q = next(q for q in PART2.questions if q.type == "single")
    assert option_order(PART2, q, None) == q.options
    assert option_order(PART2, q, 3) == option_order(PART2, q, 3)
