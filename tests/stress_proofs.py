"""One submission, one score, under load: grade known-bad variants beside busy loops, again
and again, and check that each loses exactly its expected set every time.

Not part of the suite (it takes minutes per exercise). Each round grades every chosen
variant (two at a time, as ``grade-batch --jobs 2`` does on a 2-core machine) while
``--busy`` processes spin ``while True: pass``; a variant passes when every round lost
exactly its ``loses``, its feedback fits ``says`` and ``not_says``, and it got the same
score as in its first round, test by test (one submission, one score)::

    python tests/stress_proofs.py                          # every exercise, every known-bad
    python tests/stress_proofs.py timer_sync callback_groups:shared_group,deadlock
    python tests/stress_proofs.py error_handling --repeats 3 --correct

Exit status 0: every variant exact in every round; 1: some were not (each difference
printed with what the lost tests said).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from proving import (
    JOBS,
    NOT_PROOFS,
    SUBMISSIONS,
    Variant,
    failures,
    feedback_mismatches,
    load_variants,
)

from autograder.core.exercise import find_exercise
from autograder.core.results import RunResult
from autograder.grading.run import grade

BUSY = "while True: pass"


def _chosen(specs: list[str], correct: bool) -> list[tuple[str, Variant]]:
    """(exercise, variant) for each ``EXERCISE`` or ``EXERCISE:NAME,NAME`` asked for."""
    if not specs:
        specs = sorted(p.name for p in SUBMISSIONS.iterdir()
                       if p.is_dir() and p.name not in NOT_PROOFS)
    kinds = ("mutant", "broken", "correct") if correct else ("mutant", "broken")
    chosen = []
    for spec in specs:
        exercise_id, _sep, names = spec.partition(":")
        variants = load_variants(find_exercise(exercise_id))
        wanted = names.split(",") if names else [n for n, v in variants.items()
                                                  if v.kind in kinds]
        unknown = set(wanted) - set(variants)
        if unknown:
            raise SystemExit(f"{exercise_id}: no variants {', '.join(sorted(unknown))}")
        chosen += [(exercise_id, variants[name]) for name in wanted]
        if correct and not names:
            solution = find_exercise(exercise_id).solution
            chosen.append((exercise_id, Variant("reference", solution.parent, "correct",
                                                "the reference solution", frozenset())))
    return chosen


def _difference(result: RunResult | BaseException, variant: Variant) -> str | None:
    """What differs from the expectation in one grading (None: nothing)."""
    if isinstance(result, BaseException):
        return f"the grading crashed: {type(result).__name__}: {result}"
    if result.grader_error is not None:
        return f"grader error: {result.grader_error}"
    lost = {t.name for t in result.tests if t.status != "passed"}
    parts = []
    if lost != variant.loses:
        parts.append(f"lost {sorted(lost)}; expected {sorted(variant.loses)}")
    wrong = feedback_mismatches(result, variant)
    if wrong:
        parts.append(f"feedback: {wrong}")
    return "; ".join(parts) or None


def _scores(result: RunResult | BaseException) -> dict[str, str] | None:
    """Each test's score, as the report gives it (None: no result to compare)."""
    if isinstance(result, BaseException) or result.grader_error is not None:
        return None
    return {t.name: str(t.score) for t in result.tests}


def _score_difference(first: dict[str, str] | None, now: dict[str, str] | None) -> str | None:
    """How a round's scores differ from the first round's (None: the same, or no pair)."""
    if first is None or now is None or first == now:
        return None
    changed = sorted(name for name in first.keys() | now.keys()
                     if first.get(name) != now.get(name))
    return "scores differ from round 1: " + ", ".join(
        f"{name} {first.get(name)} -> {now.get(name)}" for name in changed)


def _paced(result: RunResult) -> str:
    """How the world held its ticks in each module, where it was not simply for an idle
    node: which way a lost test's sim time may have run ahead of the node."""
    notable = ("budget", "unheard", "cap", "late_deliveries", "bursts", "late_commands",
               "longest_hold")
    return "; ".join(
        f"{module}: " + ", ".join(f"{key}={counts[key]}" for key in notable
                                  if counts.get(key))
        for module, counts in sorted((m, p.to_dict()) for m, p in result.pacing.items()))


def _round(chosen: list[tuple[str, Variant]], workdir: Path,
           jobs: int) -> list[RunResult | BaseException]:
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = []
        for exercise_id, variant in chosen:
            exercise = find_exercise(exercise_id)
            folder = variant.submission(exercise, workdir / exercise_id)
            futures.append(pool.submit(grade, exercise, folder))
        return [f.exception() or f.result() for f in futures]  # a crash is a difference


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("specs", nargs="*", metavar="EXERCISE[:VARIANT,...]")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--busy", type=int, default=2, help="busy loops beside the gradings")
    parser.add_argument("--jobs", type=int, default=JOBS, help="gradings at a time")
    parser.add_argument("--correct", action="store_true",
                        help="also the reference and the correct designs (they must "
                             "lose nothing)")
    args = parser.parse_args(argv)
    chosen = _chosen(args.specs, args.correct)
    print(f"{len(chosen)} variants x {args.repeats} rounds, {args.jobs} gradings at a time, "
          f"beside {args.busy} busy loops", flush=True)
    exact: Counter[str] = Counter()
    differences: dict[str, list[str]] = {}
    first_scores: dict[str, dict[str, str] | None] = {}
    busy = [subprocess.Popen([sys.executable, "-c", BUSY]) for _ in range(args.busy)]
    started = time.monotonic()
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for round_ in range(1, args.repeats + 1):
                results = _round(chosen, Path(tmp), args.jobs)
                for (exercise_id, variant), result in zip(chosen, results, strict=True):
                    key = f"{exercise_id}/{variant.name}"
                    difference = _difference(result, variant)
                    scores = _scores(result)
                    if first_scores.get(key) is None:
                        first_scores[key] = scores
                    changed = _score_difference(first_scores[key], scores)
                    if changed is not None:
                        difference = f"{difference}; {changed}" if difference else changed
                    if difference is None:
                        exact[key] += 1
                    else:
                        said = "" if isinstance(result, BaseException) else \
                            f"score {result.score}/{result.max_score}: "
                        told = "" if isinstance(result, BaseException) else \
                            f"\n      said: {failures(result)}\n      paced: {_paced(result)}"
                        differences.setdefault(key, []).append(
                            f"round {round_}: {said}{difference}{told}")
                print(f"round {round_} done, {time.monotonic() - started:.0f} s",
                      flush=True)
    finally:
        for process in busy:
            process.kill()
            process.wait()
    for exercise_id, variant in chosen:
        key = f"{exercise_id}/{variant.name}"
        print(f"{key}: exact in {exact[key]}/{args.repeats}")
        for line in differences.get(key, []):
            print(f"    {line}")
    return 1 if differences else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
