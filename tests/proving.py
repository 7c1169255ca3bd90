"""How every exercise proves its tests: grade its reference solution (several times,
beside other gradings), its starter and every submission under
``tests/submissions/<exercise>/``, then check what each scored.

A submission folder is data: ``expect.yaml`` says what it is and which tests it must lose,
as an exact set::

    kind: mutant            # correct | mutant (a known flaw) | broken (does not run right)
    why: relays linear.x unclamped
    loses: [test_clamps_linear, test_speed_stays_under_limit]
    says:                   # optional: what a lost test's message or hint must name
      test_clamps_linear: ["linear.x=3.0 was passed on unclamped"]
    not_says:               # optional: advice it must not give (the variant follows it)
      test_clamps_linear: ["declare_parameter"]

and the program is either the exercise's file itself (an alternative correct design,
written its own way) or ``<file>.patch``: a unified diff against the exercise's reference
solution, so a known-bad variant's flaw reads in a few lines. Patches are applied here,
in Python, to a copy (no ``patch`` program needed).

An exercise's proof module (``tests/test_grading_<exercise>.py``) declares
``PROOF = Proof(...)`` and its own special checks; ``tests/conftest.py`` adds the
STANDARD_CHECKS below to it, grades the PROOF once per module (the ``graded`` fixture) and
parametrizes ``correct`` and ``known_bad`` from the folders.

    python tests/proving.py losses EXERCISE    # grade everything, print what each lost
                                               # and what each lost test said
    python tests/proving.py patch FOLDER       # turn a full copy into FILE.patch
    python tests/proving.py sim-seconds EXERCISE  # each test's simulation seconds
"""

from __future__ import annotations

import ast
import dataclasses
import difflib
import functools
import json
import os
import re
import statistics
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import yaml

from autograder.commands.exercise_checks import WALL_TIME, simulation_seconds
from autograder.core.exercise import Exercise, find_exercise
from autograder.core.results import RunResult
from autograder.grading.run import grade
from content.course import course_root

SUBMISSIONS = Path(__file__).parent / "submissions"
# Gradings at a time: two, as `grade-batch --jobs 2` on this 2-core machine (three made the
# proofs no faster: each waits on its longest chain of gradings, not on the CPU).
JOBS = int(os.environ.get("AUTOGRADER_TEST_JOBS", "2"))
EXPECT = "expect.yaml"
KINDS = ("correct", "mutant", "broken")
# Folders under tests/submissions that are not an exercise's proof: test_hostile.py's
# corpus, and the programs test_shapes.py grades alone (they would starve a grading beside).
NOT_PROOFS = ("hostile", "stalls")


class PatchError(ValueError):
    """A patch that is malformed or does not fit the file it is applied to."""


# -- patches ---------------------------------------------------------------------------------

_HUNK = re.compile(r"@@ -(\d+)(?:,(\d+))? \+(\d+)(?:,(\d+))? @@")


def make_patch(solution: str, variant: str, file: str, name: str) -> str:
    """The unified diff that turns ``solution`` into ``variant`` (3 lines of context)."""
    for label, text in (("solution", solution), (name, variant)):
        if text and not text.endswith("\n"):  # difflib has no "No newline" marker
            raise PatchError(f"{label}/{file} does not end with a newline")
    return "".join(difflib.unified_diff(solution.splitlines(keepends=True),
                                        variant.splitlines(keepends=True),
                                        f"solution/{file}", f"{name}/{file}"))


def apply_patch(original: str, patch: str) -> str:
    """``original`` with the unified diff ``patch`` applied.

    Every hunk's old lines must match exactly, context included (no fuzz: a patch that
    no longer fits the solution fails loudly rather than making some other program). A
    hunk is looked for at the line it names first, then ever further up and down, so
    lines added or removed elsewhere in the solution only move it.
    """
    source = original.splitlines(keepends=True)
    result: list[str] = []
    done = 0  # source lines before this are copied or replaced
    for start, old, new in _hunks(patch):
        at = _find(source, old, start, done)
        if at is None:
            raise PatchError(f"hunk at line {start + 1} does not match the file:\n"
                             + "".join(old))
        result += source[done:at] + new
        done = at + len(old)
    return "".join(result + source[done:])


def _hunks(patch: str) -> list[tuple[int, list[str], list[str]]]:
    """Each hunk as (0-based line it starts at, old lines, new lines)."""
    lines = patch.splitlines(keepends=True)
    hunks: list[tuple[int, list[str], list[str]]] = []
    i = 0
    while i < len(lines):
        match = _HUNK.match(lines[i])
        i += 1
        if match is None:
            if hunks:  # only the ---/+++ header may come before the first hunk
                raise PatchError(f"not a hunk: {lines[i - 1]!r}")
            continue
        old_count = int(match[2] if match[2] is not None else 1)
        new_count = int(match[4] if match[4] is not None else 1)
        # An empty old side names the line *after which* the new lines go.
        start = int(match[1]) - (1 if old_count else 0)
        old: list[str] = []
        new: list[str] = []
        tag = ""
        while len(old) < old_count or len(new) < new_count \
                or (i < len(lines) and lines[i].startswith("\\")):
            if i >= len(lines):
                raise PatchError(f"hunk {match[0]} ends early")
            line = lines[i]
            i += 1
            if line.startswith("\\"):  # "\ No newline at end of file": the line before
                for side, tags in ((old, " -"), (new, " +")):
                    if tag and tag in tags:
                        side[-1] = side[-1].removesuffix("\n")
                continue
            if line in ("\n", "\r\n"):  # a blank context line whose space an editor trimmed
                line = " " + line
            tag = line[:1]
            if tag not in (" ", "-", "+"):
                raise PatchError(f"hunk {match[0]}: unexpected line {line!r}")
            if tag in " -":
                old.append(line[1:])
            if tag in " +":
                new.append(line[1:])
        if len(old) != old_count or len(new) != new_count:
            raise PatchError(f"hunk {match[0]}: line counts do not match")
        hunks.append((start, old, new))
    if not hunks:
        raise PatchError("no hunks")
    return hunks


def _find(source: list[str], old: list[str], start: int, earliest: int) -> int | None:
    """Where ``old`` occurs in ``source`` at or after ``earliest``, nearest ``start``."""
    last = len(source) - len(old)
    for offset in range(max(start - earliest, last - start) + 1):
        for at in (start - offset, start + offset):
            if earliest <= at <= last and source[at:at + len(old)] == old:
                return at
    return None


# -- submissions -----------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Variant:
    """One submission folder of an exercise's proof, and what it must lose."""

    name: str
    folder: Path
    kind: str
    why: str
    loses: frozenset[str]
    # For a lost test, words its feedback (message or hint, in English) must contain: the
    # value or case that failed and the fix for it, not a generic reminder of the API.
    says: tuple[tuple[str, tuple[str, ...]], ...] = ()
    # For a lost test, words its feedback must not contain: advice the variant already
    # follows (a hint chosen from what was observed never repeats what the code does).
    not_says: tuple[tuple[str, tuple[str, ...]], ...] = ()
    # The correct design (a sibling folder) the patch applies to; None: the solution. A
    # one-flaw variant of a design written its own way reads as its flaw too.
    base: str | None = None

    def program(self, exercise: Exercise) -> str:
        """The submitted file's text: the folder's own copy, or the patched solution (or
        patched ``base`` design)."""
        own = self.folder / exercise.file
        if own.exists():
            return own.read_text(encoding="utf-8")
        patch = self.folder / f"{exercise.file}.patch"
        original = exercise.solution if self.base is None else \
            self.folder.parent / self.base / exercise.file
        try:
            return apply_patch(original.read_text(encoding="utf-8"),
                               patch.read_text(encoding="utf-8"))
        except PatchError as exc:
            raise PatchError(f"{patch}: {exc}") from None

    def submission(self, exercise: Exercise, workdir: Path) -> Path:
        """A folder to grade: the variant's own, or a copy in ``workdir`` with the patch
        applied."""
        if (self.folder / exercise.file).exists():
            return self.folder
        target = workdir / self.name
        target.mkdir(parents=True, exist_ok=True)
        (target / exercise.file).write_text(self.program(exercise), encoding="utf-8")
        return target


def load_variant(folder: Path, exercise: Exercise) -> Variant:
    """A submission folder and its ``expect.yaml``, checked: a typo in an expectation must
    not quietly weaken a proof."""
    path = folder / EXPECT

    def wrong(what: str) -> ValueError:
        return ValueError(f"{path}: {what}")

    if not path.exists():
        raise wrong("missing: every submission folder says what it must lose")
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    if not isinstance(data, dict) or not {"kind", "why", "loses"} <= set(data) \
            or set(data) - {"kind", "why", "loses", "says", "not_says", "base"}:
        # No "may also lose": a loss that depends on the machine's load is a test to fix
        # (one submission, one score; tests/stress_proofs.py holds every proof to it).
        raise wrong("needs the keys kind, why and loses (and may have says, not_says, "
                    "base)")
    kind, why, loses = data["kind"], data["why"], data["loses"]
    if kind not in KINDS:
        raise wrong(f"kind must be one of {', '.join(KINDS)}, not {kind!r}")
    if not isinstance(why, str) or not why.strip() or "\n" in why.strip():
        raise wrong("why must be one line")
    if not isinstance(loses, list) or not all(isinstance(t, str) for t in loses) \
            or len(set(loses)) != len(loses):
        raise wrong("loses must be a list of distinct test names")
    if (kind == "correct") != (not loses):
        raise wrong("a correct design loses no test; every other kind loses some")
    unknown = set(loses) - exercise_tests(exercise)
    if unknown:
        raise wrong(f"no such tests in {exercise.id}: {', '.join(sorted(unknown))}")
    says, not_says = data.get("says", {}), data.get("not_says", {})
    for key, words_of in (("says", says), ("not_says", not_says)):
        if not isinstance(words_of, dict) or not set(words_of) <= set(loses) or not all(
                isinstance(words, list) and words
                and all(isinstance(w, str) and w.strip() for w in words)
                for words in words_of.values()):
            raise wrong(f"{key} maps tests in loses to lists of words their feedback "
                        f"{'names' if key == 'says' else 'must not name'}")
    files = [p for p in (folder / exercise.file, folder / f"{exercise.file}.patch")
             if p.exists()]
    if len(files) != 1:
        raise wrong(f"needs {exercise.file} or {exercise.file}.patch, and only one")
    base = data.get("base")
    if base is not None and (
            not isinstance(base, str) or kind == "correct"
            or not (folder.parent / base / exercise.file).is_file()
            or (yaml.safe_load((folder.parent / base / EXPECT).read_text(encoding="utf-8"))
                or {}).get("kind") != "correct"):
        raise wrong(f"base names a correct design of {exercise.id} written as a whole file")
    return Variant(folder.name, folder, kind, why.strip(), frozenset(loses),
                   tuple((test, tuple(words)) for test, words in sorted(says.items())),
                   tuple((test, tuple(words)) for test, words in sorted(not_says.items())),
                   base)


def load_variants(exercise: Exercise) -> dict[str, Variant]:
    folder = SUBMISSIONS / exercise.id
    return {p.name: load_variant(p, exercise) for p in sorted(folder.iterdir()) if p.is_dir()}


@functools.cache
def exercise_tests(exercise: Exercise) -> frozenset[str]:
    """The names of the exercise's test functions, public and hidden (read, not imported)."""
    names: set[str] = set()
    for path in sorted(exercise.folder.glob("tests/**/test_*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) \
                    and node.name.startswith("test"):
                names.add(node.name)
    return frozenset(names)


# -- the proof -------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Proof:
    exercise: str
    repeats: int = 5
    jobs: int = JOBS

    @functools.cached_property
    def variants(self) -> dict[str, Variant]:
        return load_variants(find_exercise(self.exercise))

    def named(self, *kinds: str) -> list[str]:
        return [name for name, v in self.variants.items() if v.kind in kinds]

    def grade_all(self, workdir: Path) -> dict[str, RunResult]:
        exercise = find_exercise(self.exercise)
        jobs: dict[str, Path | None] = {f"reference#{i}": None for i in range(self.repeats)}
        jobs["starter"] = exercise.starter
        for name, variant in self.variants.items():
            jobs[name] = variant.submission(exercise, workdir)
        with ThreadPoolExecutor(max_workers=self.jobs) as pool:
            futures = {name: pool.submit(grade, exercise, path) for name, path in jobs.items()}
            return {name: future.result() for name, future in futures.items()}


def failed_tests(result: RunResult) -> set[str]:
    return set(failures(result))


def failures(result: RunResult) -> dict[str, str]:
    """What each lost test said, so a failed proof in CI says why and not only which."""
    return {t.name: f"{t.status}: {t.message}" for t in result.tests if t.status != "passed"}


def explain(**parts: Any) -> str:
    """An assertion message in full: pytest cuts a dict's repr short, never a string."""
    return json.dumps(parts, indent=1, ensure_ascii=False, default=str)


def diagnosis(result: RunResult) -> dict[str, Any]:
    """What a failed proof prints of a grading: what each lost test said and measured, how
    the world paced itself, where the time went (a verdict that changed under load says
    why)."""
    charts = {t.name: [c.to_dict() for c in t.charts] for t in result.tests
              if t.status != "passed" and t.charts}
    return {"lost": failures(result), "grader_error": result.grader_error,
            "grader_details": result.grader_details[-2000:],
            # What the lost tests measured (e.g. when each rate report came), so a verdict
            # that changed only now and then can be read from CI's log.
            **({"charts": charts} if charts else {}),
            **({"pacing": {m: p.to_dict() for m, p in result.pacing.items()}}
               if result.pacing else {}),
            **({"timing": result.timing.to_dict()} if result.timing is not None else {})}


_BOTH_TYPES = (re.compile(r"geometry_msgs/msg/Twist\b"),
               re.compile(r"geometry_msgs/msg/TwistStamped\b"))


def without_both_types(result: RunResult) -> dict[str, str]:
    """The lost tests whose feedback does not name both Twist and TwistStamped: a node
    written for Jazzy's TurtleBot3 must be told why its commands never arrived."""
    return {t.name: t.message for t in result.tests if t.status != "passed"
            and not all(pattern.search(t.message) for pattern in _BOTH_TYPES)}


def test_reference_scores_full_marks_every_time(graded: dict[str, RunResult],
                                                proof: Proof) -> None:
    results = [graded[f"reference#{i}"] for i in range(proof.repeats)]
    assert [r.grader_error for r in results] == [None] * proof.repeats, explain(
        runs=[diagnosis(r) for r in results])
    assert all(r.score == r.max_score for r in results), explain(
        runs=[diagnosis(r) for r in results])
    assert len({r.max_score for r in results}) == 1
    assert all(r.passed for r in results)


def test_starter_is_below_the_pass_mark(graded: dict[str, RunResult]) -> None:
    result = graded["starter"]
    assert result.grader_error is None, explain(**diagnosis(result))
    assert not result.passed
    assert result.score < result.max_score * result.pass_mark
    assert result.core_missed, "the starter passes every core test"  # as validate has it


def test_other_correct_designs_score_full_marks(graded: dict[str, RunResult],
                                                correct: str) -> None:
    result = graded[correct]
    assert result.grader_error is None, explain(**diagnosis(result))
    assert result.score == result.max_score, explain(**diagnosis(result))


def test_known_bad_variant_loses_exactly_the_tests_aimed_at_it(
        graded: dict[str, RunResult], proof: Proof, known_bad: str) -> None:
    """Exactly: a variant that loses more than intended points at a test that checks more
    than its name says, or at a flaw other than the one its folder names."""
    result = graded[known_bad]
    variant = proof.variants[known_bad]
    assert result.grader_error is None, explain(**diagnosis(result))
    assert result.score < result.max_score
    lost = failed_tests(result)
    assert lost == variant.loses, explain(
        why=variant.why, **{
            "passed, though expected lost": sorted(variant.loses - lost),
            "lost, though not expected": sorted(lost - variant.loses)},
        **diagnosis(result))


def test_known_bad_variant_passes_only_with_every_core_test(
        graded: dict[str, RunResult], proof: Proof, known_bad: str) -> None:
    """A variant that loses a core test (exercise.yaml's ``core``) does not pass, whatever
    its points, and its results name exactly the core tests it lost; one that loses none
    passes or not by its points alone."""
    result = graded[known_bad]
    variant = proof.variants[known_bad]
    core = set(find_exercise(proof.exercise).core)
    assert core, f"{proof.exercise} names no core tests"
    lost_core = failed_tests(result) & core
    assert {t.name for t in result.core_missed} == lost_core, explain(**diagnosis(result))
    assert variant.loses & core <= lost_core
    assert result.passed == (result.fraction >= result.pass_mark and not lost_core), explain(
        why=variant.why, core_lost=sorted(lost_core), **diagnosis(result))
    if variant.loses & core:
        assert not result.passed


def test_known_bad_variant_is_told_what_was_observed(
        graded: dict[str, RunResult], proof: Proof, known_bad: str) -> None:
    """A lost test names the value or case that failed and its fix (``says``), and gives
    no advice the variant already follows (``not_says``)."""
    wrong = feedback_mismatches(graded[known_bad], proof.variants[known_bad])
    assert not wrong, explain(**wrong)


def feedback_mismatches(result: RunResult, variant: Variant) -> dict[str, Any]:
    """For each lost test, the ``says`` words its feedback lacks and the ``not_says`` words
    it has (empty: the feedback fits the variant)."""
    by_name = {t.name: t for t in result.tests}
    wrong: dict[str, Any] = {}
    checks = [(test, words, False) for test, words in variant.says] + \
        [(test, words, True) for test, words in variant.not_says]
    for test, words, present in checks:
        found = by_name.get(test)
        text = f"{found.message}\n{found.hint}" if found else ""
        bad = [w for w in words if (w in text) == present]
        if bad:
            entry = wrong.setdefault(test, {"message": found.message if found else None,
                                            "hint": found.hint if found else None})
            entry["says, though it must not" if present else "missing"] = bad
    return wrong


def test_each_hint_is_given_once(graded: dict[str, RunResult]) -> None:
    """A hint is not repeated in its own test's message (one place for the fix)."""
    repeated = {f"{name}: {t.name}": t.hint for name, result in graded.items()
                for t in result.tests if t.hint and t.hint.strip() in t.message}
    assert not repeated


def references_simulation_seconds(graded: dict[str, RunResult]) -> dict[str, float]:
    """Each test's simulation seconds to its verdict (setup and call: a module's shared run
    counts in its first test), the median over the reference's gradings."""
    runs: dict[str, list[float]] = {}
    for name, result in graded.items():
        if name.startswith("reference#") and result.timing is not None:
            for nodeid, seconds in result.timing.sim_seconds.items():
                runs.setdefault(nodeid.rpartition("::")[2], []).append(seconds)
    return {test: statistics.median(values) for test, values in runs.items()}


# A test's simulation seconds move with when the node reacts, and a service call's or a
# discovery's wall time passes in simulation time at the world's pace (callback_groups'
# test_ignores_invalid_readings read 3.0 s on a loaded machine, 4.1 s in a quiet CI run):
# the README gives them to a tenth, and they hold within this much (seconds, or a
# fraction of them).
SIM_SECONDS_SLACK = (1.5, 0.25)


def test_readme_gives_each_tests_simulation_seconds(graded: dict[str, RunResult],
                                                     proof: Proof) -> None:
    """Each README's grading table gives the simulation seconds each test takes to its
    verdict, as the reference's gradings measure them: what a grading's wall time
    approaches at the exercise's pace (issue 36, "know the floor")."""
    exercise = find_exercise(proof.exercise)
    measured = references_simulation_seconds(graded)
    wrong = {}
    for readme, given in simulation_seconds(exercise, course_root()).items():
        for test, seconds in given.items():
            real = measured.get(test)
            if real is None or seconds == WALL_TIME:  # its exit, timed on the wall clock
                continue
            slack = max(SIM_SECONDS_SLACK[0], SIM_SECONDS_SLACK[1] * real)
            if not isinstance(seconds, float) or abs(seconds - real) > slack:
                wrong[f"{readme}: {test}"] = {"README": seconds, "measured": round(real, 1)}
    assert not wrong, explain(**wrong)


# What every exercise's proof checks: tests/conftest.py adds these to each module that
# declares PROOF, parametrized from its submission folders (``correct``, ``known_bad``).
STANDARD_CHECKS = (test_reference_scores_full_marks_every_time,
                   test_starter_is_below_the_pass_mark,
                   test_other_correct_designs_score_full_marks,
                   test_known_bad_variant_loses_exactly_the_tests_aimed_at_it,
                   test_known_bad_variant_passes_only_with_every_core_test,
                   test_known_bad_variant_is_told_what_was_observed,
                   test_each_hint_is_given_once,
                   test_readme_gives_each_tests_simulation_seconds)


# -- tools -----------------------------------------------------------------------------------

def _losses(exercise_id: str) -> None:
    """Grade every submission of an exercise and print what each lost and what each lost
    test said, beside what its ``expect.yaml`` says: where an expectation comes from."""
    proof = Proof(exercise_id)
    with tempfile.TemporaryDirectory() as tmp:
        results = proof.grade_all(Path(tmp))
    for name, result in results.items():
        lost = sorted(failed_tests(result))
        variant = proof.variants.get(name)
        fits = variant is None or variant.loses == set(lost)
        mark = "" if fits else "  # differs"
        print(f"{name}: score {result.score}/{result.max_score}, "
              f"grader_error {result.grader_error}{mark}\n  loses: [{', '.join(lost)}]")
        for test in result.tests:  # what each lost test said: where `says` comes from
            if test.name in lost:
                print(f"    {test.name}: {test.message.splitlines()[0] if test.message else ''}"
                      f"\n      hint: {test.hint}")


def _patch(folder: Path) -> None:
    """Replace a variant's full copy with a patch against the solution, after checking
    that the patch gives the copy back byte for byte."""
    exercise = find_exercise(folder.resolve().parent.name)
    copy = folder / exercise.file
    expect = yaml.safe_load((folder / EXPECT).read_text(encoding="utf-8")) \
        if (folder / EXPECT).exists() else {}
    base = exercise.solution if not expect.get("base") else \
        folder.parent / expect["base"] / exercise.file
    solution, variant = (p.read_text(encoding="utf-8") for p in (base, copy))
    patch = make_patch(solution, variant, exercise.file, folder.name)
    if apply_patch(solution, patch) != variant:
        raise PatchError(f"{copy}: the patch does not give the file back")
    (folder / f"{exercise.file}.patch").write_text(patch, encoding="utf-8")
    copy.unlink()
    print(f"{copy}: {len(variant.splitlines())} lines -> patch of {len(patch.splitlines())}")


def _sim_seconds(exercise_id: str) -> None:
    """Grade the reference three times and print each test's simulation seconds (the
    median), for the READMEs' grading tables."""
    exercise = find_exercise(exercise_id)
    graded = {f"reference#{i}": grade(exercise, None) for i in range(3)}
    for test, seconds in references_simulation_seconds(graded).items():
        print(f"{test}: {seconds:.1f}")


def main(argv: list[str]) -> int:
    if len(argv) == 2 and argv[0] == "losses":
        _losses(argv[1])
    elif len(argv) == 2 and argv[0] == "sim-seconds":
        _sim_seconds(argv[1])
    elif len(argv) >= 2 and argv[0] == "patch":
        for folder in argv[1:]:
            _patch(Path(folder))
    else:
        print(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
