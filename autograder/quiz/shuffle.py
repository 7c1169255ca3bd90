"""Per-attempt option order: the same seed gives the same order, pinned options stay put.

Each question type decides how its options are ordered (``QuestionType.option_order``);
the random source and the pinned-options shuffle they share are here.
"""

from __future__ import annotations

import random

from autograder.quiz.model import Option, Question, Quiz
from autograder.quiz.types import question_type


def attempt_rng(seed: str | int, quiz: Quiz, question: Question) -> random.Random:
    """The random source of one question in one attempt."""
    # A string seed is hashed by random with SHA-512: stable across runs and platforms.
    return random.Random(f"{seed}:{quiz.id}:{question.id}")


def shuffle_unpinned(options: tuple[Option, ...], rng: random.Random) -> tuple[Option, ...]:
    """Shuffle the options that are not pinned; a pinned one keeps its place."""
    free = [o for o in options if not o.pin]
    rng.shuffle(free)
    it = iter(free)
    return tuple(o if o.pin else next(it) for o in options)


def option_order(quiz: Quiz, question: Question, seed: str | int | None) -> tuple[Option, ...]:
    """The options of ``question`` in the order one attempt shows them."""
    return question_type(question.type).option_order(quiz, question, seed)
