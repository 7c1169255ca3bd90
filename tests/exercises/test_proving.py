"""The proofs' data, checked without grading: every submission folder says what it must
lose in a well-formed expect.yaml, every patch still fits its exercise's reference
solution, and the patches are applied exactly (tests/proving.py).

The proofs themselves (tests/test_grading_*.py) take minutes; a stale patch or a typo in an
expectation shows here in a second.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import proving
import pytest
from proving import (
    NOT_PROOFS,
    SUBMISSIONS,
    PatchError,
    Proof,
    apply_patch,
    exercise_tests,
    load_variant,
    load_variants,
    make_patch,
    without_both_types,
)

from autograder.core.exercise import find_exercise

TESTS = Path(__file__).parents[1]
EXERCISES = sorted(p.name for p in SUBMISSIONS.iterdir() if p.name not in NOT_PROOFS)
FOLDERS = [SUBMISSIONS / e / v for e in EXERCISES for v in sorted(
    p.name for p in (SUBMISSIONS / e).iterdir() if p.is_dir())]


@pytest.mark.parametrize("exercise", EXERCISES)
def test_each_exercise_with_submissions_has_its_proof_module(exercise: str) -> None:
    module = TESTS / f"test_grading_{exercise}.py"
    assert module.exists()
    assert f'PROOF = Proof("{exercise}"' in module.read_text()


@pytest.mark.parametrize("folder", FOLDERS, ids=lambda f: f"{f.parent.name}/{f.name}")
def test_each_submission_is_a_program_and_an_expectation(folder: Path) -> None:
    exercise = find_exercise(folder.parent.name)
    variant = load_variant(folder, exercise)  # raises on anything malformed
    program = variant.program(exercise)
    assert program != exercise.solution.read_text(encoding="utf-8")
    assert variant.loses <= exercise_tests(exercise)
    if variant.kind == "correct":
        compile(program, exercise.file, "exec")  # a correct design at least compiles


@pytest.mark.parametrize("exercise", EXERCISES)
def test_known_bad_variants_are_patches(exercise: str) -> None:
    """A known-bad variant is a patch against the solution, so its flaw reads in a few
    lines; only correct designs written their own way are whole files."""
    info = find_exercise(exercise)
    for name, variant in load_variants(info).items():
        if variant.kind != "correct":
            assert (variant.folder / f"{info.file}.patch").exists(), name


def expectation(tmp_path: Path, text: str) -> Path:
    folder = tmp_path / "submissions" / "bad"
    folder.mkdir(parents=True)
    (folder / "expect.yaml").write_text(text)
    (folder / "velocity_governor.py").write_text("pass\n")
    return folder


@pytest.mark.parametrize("text,problem", [
    ("kind: mutant\nwhy: x\nloses: []\n", "every other kind loses some"),
    ("kind: correct\nwhy: x\nloses: [test_node_starts]\n", "a correct design loses no test"),
    ("kind: mutant\nwhy: x\nloses: [test_no_such_thing]\n", "no such tests"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts, test_node_starts]\n", "distinct"),
    ("kind: mutatn\nwhy: x\nloses: [test_node_starts]\n", "kind must be one of"),
    ("kind: mutant\nloses: [test_node_starts]\n", "needs the keys kind, why and loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\naimed: []\n",
     "needs the keys kind, why and loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nmay_also_lose: [test_clamps_linear]\n",
     "needs the keys kind, why and loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nsays: {test_clamps_linear: [a]}\n",
     "says maps tests in loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nsays: {test_node_starts: []}\n",
     "says maps tests in loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nsays: {test_node_starts: a}\n",
     "says maps tests in loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nsays: [test_node_starts]\n",
     "says maps tests in loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nnot_says: {test_clamps_linear: [a]}\n",
     "not_says maps tests in loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nnot_says: {test_node_starts: []}\n",
     "not_says maps tests in loses"),
    ("kind: mutant\nwhy: x\nloses: [test_node_starts]\nbase: no_such_design\n",
     "base names a correct design"),
])
def test_a_malformed_expectation_is_refused(tmp_path: Path, text: str, problem: str) -> None:
    """A typo must not quietly weaken a proof."""
    folder = expectation(tmp_path, text)
    with pytest.raises(ValueError, match=problem):
        load_variant(folder, find_exercise("parameter_validation"))


def test_feedback_must_name_what_says_lists_and_nothing_not_says_lists(
        tmp_path: Path) -> None:
    """``says`` words missing and ``not_says`` words present are both reported, each
    under its test; feedback that fits reports nothing."""
    folder = expectation(tmp_path, "kind: mutant\nwhy: x\nloses: [test_node_starts]\n"
                         "says: {test_node_starts: [observed]}\n"
                         "not_says: {test_node_starts: [already done, MultiThreadedExecutor]}\n")
    variant = load_variant(folder, find_exercise("parameter_validation"))

    def graded(message: str, hint: str) -> SimpleNamespace:
        return SimpleNamespace(tests=[SimpleNamespace(name="test_node_starts",
                                                      message=message, hint=hint)])

    assert proving.feedback_mismatches(graded("what was observed", "fix it"), variant) == {}
    wrong = proving.feedback_mismatches(
        graded("nothing", "spin a MultiThreadedExecutor"), variant)["test_node_starts"]
    assert wrong["missing"] == ["observed"]
    assert wrong["says, though it must not"] == ["MultiThreadedExecutor"]


def test_a_one_flaw_variant_of_a_blind_design_is_a_patch_against_that_design() -> None:
    """``base``: the patch applies to the sibling correct design, not to the solution."""
    info = find_exercise("parameter_validation")
    variants = load_variants(info)
    flawed = variants["startup_no_upper_bound"]
    base = (flawed.folder.parent / flawed.base / info.file).read_text(encoding="utf-8")
    assert flawed.base == "functional_partial" and variants[flawed.base].kind == "correct"
    program = flawed.program(info)
    assert "must be at least" in program and "must be at least" not in base
    assert program.splitlines()[10:40] == base.splitlines()[10:40]  # the design is kept


def test_a_folder_with_both_a_file_and_a_patch_is_refused(tmp_path: Path) -> None:
    folder = expectation(tmp_path, "kind: mutant\nwhy: x\nloses: [test_node_starts]\n")
    (folder / "velocity_governor.py.patch").write_text("")
    with pytest.raises(ValueError, match="only one"):
        load_variant(folder, find_exercise("parameter_validation"))


SOLUTION = "".join(f"line {i}\n" for i in range(1, 21))


def edited(text: str) -> str:
    return text.replace("line 3\n", "line three\n").replace("line 15\n", "").replace(
        "line 20\n", "line 20\nline 21\n")


def test_a_patch_gives_the_variant_back() -> None:
    patch = make_patch(SOLUTION, edited(SOLUTION), "f.py", "v")
    assert patch.startswith("--- solution/f.py\n+++ v/f.py\n@@ ")
    assert apply_patch(SOLUTION, patch) == edited(SOLUTION)


def test_a_patch_follows_lines_that_moved() -> None:
    """Lines added above a hunk move it; the hunk is found where its context now is."""
    patch = make_patch(SOLUTION, edited(SOLUTION), "f.py", "v")
    moved = "new 1\nnew 2\n" + SOLUTION.replace("line 10\n", "")
    assert apply_patch(moved, patch) == "new 1\nnew 2\n" + edited(SOLUTION).replace(
        "line 10\n", "")


def test_a_patch_that_no_longer_fits_fails_loudly() -> None:
    patch = make_patch(SOLUTION, edited(SOLUTION), "f.py", "v")
    with pytest.raises(PatchError, match="does not match"):
        apply_patch(SOLUTION.replace("line 14\n", "line fourteen\n"), patch)


def test_a_blank_context_line_trimmed_by_an_editor_still_applies() -> None:
    solution, variant = "a\n\nb\nc\n", "a\n\nB\nc\n"
    patch = make_patch(solution, variant, "f.py", "v")
    assert "\n \n" in patch
    assert apply_patch(solution, patch.replace("\n \n", "\n\n")) == variant


def test_no_newline_at_end_of_file() -> None:
    patch = ("--- a\n+++ b\n@@ -1,2 +1,2 @@\n a\n-b\n\\ No newline at end of file\n"
             "+B\n\\ No newline at end of file\n")
    assert apply_patch("a\nb", patch) == "a\nB"


@pytest.mark.parametrize("patch,problem", [
    ("--- a\n+++ b\n", "no hunks"),
    ("--- a\n+++ b\n@@ -1,2 +1,2 @@\n a\n", "ends early"),
    ("--- a\n+++ b\n@@ -1,1 +1,1 @@\n?a\n", "unexpected line"),
])
def test_a_malformed_patch_is_refused(patch: str, problem: str) -> None:
    with pytest.raises(PatchError, match=problem):
        apply_patch("a\n", patch)


def test_says_is_read_in_order_of_tests(tmp_path: Path) -> None:
    """What a lost test's feedback must name comes through as written, per test."""
    folder = expectation(tmp_path, "kind: mutant\nwhy: x\nloses: [test_node_starts, "
                                   "test_clamps_linear]\nsays:\n  test_node_starts: [a, b]\n"
                                   "  test_clamps_linear: [c]\n")
    variant = load_variant(folder, find_exercise("parameter_validation"))
    assert variant.says == (("test_clamps_linear", ("c",)), ("test_node_starts", ("a", "b")))



@pytest.mark.parametrize("exercise", EXERCISES)
def test_feedback_expectations_are_aimed_at_lost_tests(exercise: str) -> None:
    """Every exercise states, for some known-bad variant, what its feedback must name."""
    variants = load_variants(find_exercise(exercise)).values()
    assert any(v.says for v in variants if v.kind != "correct")


def _graded(message: str, hint: str) -> dict:
    """upper_bound_only's results as the proof checks see them: its two lost tests, the
    first saying ``message`` and ``hint``."""
    tests = [SimpleNamespace(name="test_refuses_out_of_range", message=message, hint=hint),
             SimpleNamespace(name="test_invalid_override_exits",
                             message="Started with -p max_angular_speed:=-1.0, ...",
                             hint="... check the lower bound there too ...")]
    return {"upper_bound_only": SimpleNamespace(tests=tests)}


def test_the_says_check_fails_when_feedback_does_not_name_the_case() -> None:
    proof = Proof("parameter_validation")
    told = _graded("Setting max_linear_speed to -0.1 was accepted; it must be refused.",
                   "Check the lower bound too: ...")
    proving.test_known_bad_variant_is_told_what_was_observed(told, proof, "upper_bound_only")
    generic = _graded("Setting max_linear_speed to -0.1 was accepted; it must be refused.",
                      "Return `SetParametersResult(successful=False, reason=...)`.")
    with pytest.raises(AssertionError, match="lower bound"):
        proving.test_known_bad_variant_is_told_what_was_observed(generic, proof,
                                                                 "upper_bound_only")


def test_the_once_check_fails_on_a_hint_repeated_in_its_message() -> None:
    proving.test_each_hint_is_given_once(_graded("It failed.", "Fix it."))
    with pytest.raises(AssertionError):
        proving.test_each_hint_is_given_once(_graded("It failed. Fix it.", "Fix it."))


def test_both_velocity_types_must_be_named_in_every_lost_test() -> None:
    from fractions import Fraction

    from autograder.core.results import RunResult, TestResult

    def result(*messages: str) -> RunResult:
        return RunResult("exercise", "x", "X", tuple(
            TestResult(f"test_{i}", "", Fraction(0), Fraction(1), "failed", message)
            for i, message in enumerate(messages)) + (
            TestResult("test_ok", "", Fraction(1), Fraction(1), "passed"),))

    both = ("publishes geometry_msgs/msg/TwistStamped on /cmd_vel, but this robot takes "
            "geometry_msgs/msg/Twist (its cmd_vel_type)")
    assert without_both_types(result(both, both)) == {}
    stamped_only = "publishes geometry_msgs/msg/TwistStamped on /cmd_vel"
    assert without_both_types(result(both, stamped_only, "nothing on cmd_vel")) == {
        "test_1": stamped_only, "test_2": "nothing on cmd_vel"}


@pytest.mark.parametrize("exercise", EXERCISES)
def test_each_core_test_is_lost_by_a_known_bad_variant_that_then_fails(exercise: str) -> None:
    """Every core test of an exercise has a one-flaw variant in its proof that loses it, so
    the proof shows that breaking that requirement fails the grading (the check itself is
    proving's test_known_bad_variant_passes_only_with_every_core_test)."""
    core = set(find_exercise(exercise).core)
    assert core and core <= exercise_tests(find_exercise(exercise))
    lost = {test for v in load_variants(find_exercise(exercise)).values()
            if v.kind == "mutant" for test in v.loses}
    assert not core - lost, f"no mutant of {exercise} loses {sorted(core - lost)}"


def test_the_core_check_fails_a_variant_that_passes_without_a_core_test() -> None:
    """The proof's core check catches a grading that passed on points with a core test lost."""
    from fractions import Fraction

    from autograder.core.results import RunResult, TestResult

    tests = (TestResult("test_refuses_out_of_range", "refuses", Fraction(0), Fraction(2),
                        "failed"),  # core, but not marked so: the grader forgot it
             TestResult("test_node_starts", "starts", Fraction(11), Fraction(11), "passed"))
    graded = {"accepts_out_of_range": RunResult("exercise", "parameter_validation", "T",
                                                tests)}
    with pytest.raises(AssertionError):
        proving.test_known_bad_variant_passes_only_with_every_core_test(
            graded, Proof("parameter_validation"), "accepts_out_of_range")
