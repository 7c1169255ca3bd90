"""Per-attempt option order: the same seed gives the same order, pinned options stay put."""

from __future__ import annotations

import random

from autograder.quiz.model import Option, Question, Quiz


def _rng(seed: str | int, quiz: Quiz, question: Question) -> random.Random:
    # A string seed is hashed by random with SHA-512: stable across runs and platforms.
    return random.Random(f"{seed}:{quiz.id}:{question.id}")


def option_order(quiz: Quiz, question: Question, seed: str | int | None) -> tuple[Option, ...]:
    """The options of ``question`` in the order one attempt shows them.

    With no seed, choice options keep the file's order; the items of an ordering question
    are always scrambled (their file order is the answer), and never left in key order.
    """
    options = list(question.options)
    if question.type == "ordering":
        rng = _rng(quiz.id if seed is None else seed, quiz, question)
        key = list(question.answer)
        rng.shuffle(options)
        if [o.id for o in options] == key and len(options) > 1:
            options = options[1:] + options[:1]
        return tuple(options)
    if seed is None:
        return tuple(options)
    free = [o for o in options if not o.pin]
    _rng(seed, quiz, question).shuffle(free)
    it = iter(free)
    return tuple(o if o.pin else next(it) for o in options)
