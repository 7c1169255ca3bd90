"""The grading plugin's reporter (autograder.plugin.GradingReporter), run in an inner pytest.

Each test writes an exercise's test files into a minimal exercise folder, runs pytest on
them with the grader's settings document (``--autograder-settings``: the exercise and the
report's path), and reads the signed report: how each
outcome is classified (the student's failure, our error, a skip), partial credit, a
failing teardown, points and visibility. These are the verdicts every grading is built
from, checked without a simulator or a student process.
"""

from __future__ import annotations

import textwrap
from typing import Any

import pytest

from autograder.core.output_budget import CUT, DETAILS_BYTES, MESSAGE_BYTES
from autograder.core.results import IntervalChart
from autograder.core.settings import RunSettings
from autograder.core.signing import Forged, verify

EXERCISE_YAML = """\
id: mini
title: "Mini: the reporter's exercise"
file: mini.py
node: mini
hidden_visibility: hidden
core: [test_worth_three, test_secret]
"""


def grade_tests(pytester: pytest.Pytester, public: str, hidden: str = "",
                *args: str) -> dict[str, dict[str, Any]]:
    """Run the given public (and hidden) test code as an exercise's tests; the report's
    entry of each test, by name."""
    return {entry["name"]: entry
            for entry in run_report(pytester, public, hidden, *args)["tests"]}


def run_report(pytester: pytest.Pytester, public: str, hidden: str = "", *args: str,
               count_hidden: bool = False) -> dict[str, Any]:
    """The whole signed report of such a run (``count_hidden``: as ``check`` runs, the
    hidden tests only counted)."""
    folder = pytester.path / "mini"
    (folder / "tests" / "public").mkdir(parents=True)
    (folder / "exercise.yaml").write_text(EXERCISE_YAML)
    (folder / "tests" / "public" / "test_public.py").write_text(textwrap.dedent(public))
    folders = [folder / "tests" / "public"]
    if hidden:
        (folder / "tests" / "hidden").mkdir()
        (folder / "tests" / "hidden" / "test_hidden.py").write_text(textwrap.dedent(hidden))
        folders.append(folder / "tests" / "hidden")
    report = pytester.path / "report.json"
    settings = RunSettings(exercise=str(folder), report=str(report), count_only=(
        (str(folder / "tests" / "hidden"),) if count_hidden else ()))
    pytester.runpytest("-p", "no:cacheprovider", "--autograder-settings", settings.to_json(),
                       *args, *map(str, folders))
    # No key was given: the report is signed with the empty key, and only with it.
    text = report.read_text()
    with pytest.raises(Forged):
        verify(text, b"another key")
    return verify(text, b"")


def test_a_pass_is_passed_with_its_label_and_one_point(pytester: pytest.Pytester) -> None:
    tests = grade_tests(pytester, '''
        def test_ok():
            """The node starts.

            More words the student does not see in the label."""
    ''')
    entry = tests["test_ok"]
    assert (entry["status"], entry["message"], entry["hint"]) == ("passed", "", "")
    assert entry["label"] == "The node starts."
    assert entry["max_score"] == 1
    assert entry["done"] is True
    assert (entry["visibility"], entry["reveal"]) == ("visible", "message")


def test_a_student_failure_is_failed_with_its_message_and_hint(
        pytester: pytest.Pytester) -> None:
    tests = grade_tests(pytester, '''
        from autograder.core.errors import StudentFailure

        def test_clamps():
            raise StudentFailure("cmd_vel had 3.0", "clamp linear.x")
    ''')
    entry = tests["test_clamps"]
    assert (entry["status"], entry["message"], entry["hint"]) == (
        "failed", "cmd_vel had 3.0", "clamp linear.x")
    assert "StudentFailure" in entry["details"]  # the traceback, for the instructor


def test_a_failed_assertion_is_failed_with_its_message(pytester: pytest.Pytester) -> None:
    tests = grade_tests(pytester, '''
        def test_speed():
            speed = 3.0
            assert speed <= 0.5, f"the robot reached {speed} m/s"
    ''')
    entry = tests["test_speed"]
    assert entry["status"] == "failed"
    # The student reads the message, not pytest's rewritten comparison below it.
    assert entry["message"] == "the robot reached 3.0 m/s"
    assert "assert 3.0 <= 0.5" in entry["details"]


def test_any_other_exception_is_a_grader_error(pytester: pytest.Pytester) -> None:
    """A bug in a test is ours: reported as an error, never as the student's zero."""
    tests = grade_tests(pytester, '''
        from autograder.core.errors import GraderError

        def test_buggy():
            {}["missing"]

        def test_world_died():
            raise GraderError("the simulator stopped")
    ''')
    assert tests["test_buggy"]["status"] == "error"
    assert tests["test_buggy"]["message"] == "KeyError: 'missing'"
    assert "KeyError" in tests["test_buggy"]["details"]
    assert tests["test_world_died"]["status"] == "error"
    assert tests["test_world_died"]["message"] == "grader error: the simulator stopped"


def test_a_skip_is_skipped_with_its_reason(pytester: pytest.Pytester) -> None:
    tests = grade_tests(pytester, '''
        import pytest

        def test_later():
            pytest.skip("needs the corridor world")

        @pytest.mark.skip(reason="not in this term")
        def test_marked():
            pass
    ''')
    assert (tests["test_later"]["status"], tests["test_later"]["message"]) == (
        "skipped", "needs the corridor world")
    assert (tests["test_marked"]["status"], tests["test_marked"]["message"]) == (
        "skipped", "not in this term")


def test_partial_credit_is_a_failure_with_its_fraction(pytester: pytest.Pytester) -> None:
    tests = grade_tests(pytester, '''
        def test_most_of_the_way(credit):
            credit.award(0.25, "a quarter of the way", "drive on to the goal")

        def test_all_of_the_way(credit):
            credit.award(1.0, "there")

        def test_more_than_all(credit):
            credit.award(1.7, "beyond")

        def test_less_than_nothing(credit):
            credit.award(-0.5, "backwards")

        def test_award_then_fail(credit):
            credit.award(0.5, "half")
            assert False, "then it crashed"
    ''')
    entry = tests["test_most_of_the_way"]
    assert (entry["status"], entry["fraction"], entry["message"], entry["hint"]) == (
        "failed", 0.25, "a quarter of the way", "drive on to the goal")
    # A whole award is a pass (the fraction is clamped to [0, 1]); no award is kept.
    for name in ("test_all_of_the_way", "test_more_than_all"):
        assert (tests[name]["status"], tests[name]["message"]) == ("passed", ""), name
        assert tests[name]["fraction"] is None  # no award kept
    assert (tests["test_less_than_nothing"]["status"],
            tests["test_less_than_nothing"]["fraction"]) == ("failed", 0.0)
    # A failure after an award is a failure: the award is not kept.
    entry = tests["test_award_then_fail"]
    assert (entry["status"], entry["message"]) == ("failed", "then it crashed")
    assert entry["fraction"] is None


def test_a_drawn_chart_goes_in_the_report_as_its_dict(pytester: pytest.Pytester) -> None:
    """The signed report is JSON: each chart a test drew is carried as
    :meth:`IntervalChart.to_dict` writes it, and read back as the chart it was."""
    tests = grade_tests(pytester, '''
        def test_rate(evidence):
            evidence.intervals("cmd_vel", [1.0, 1.1, 1.3], limit=0.15)

        def test_no_chart():
            pass
    ''')
    (carried,) = tests["test_rate"]["charts"]
    assert carried == {"kind": "intervals", "title": "cmd_vel",
                       "points": [[1.1, 0.1], [1.3, 0.2]], "limit": 0.15}
    assert IntervalChart.from_dict(carried) == IntervalChart(
        "cmd_vel", ((1.1, 0.1), (1.3, 0.2)), 0.15)
    assert tests["test_no_chart"]["charts"] == []


def test_a_type_mismatch_leads_every_failure_once(pytester: pytest.Pytester) -> None:
    """What the module's probe saw of types that never match (plugin/msgtypes.py) comes
    first in each failed test's message, once, a module fixture's failure included; a pass
    or our own error does not get it."""
    tests = grade_tests(pytester, '''
        import pytest
        from autograder.core.errors import StudentFailure
        from autograder.plugin.stash import type_watch_key
        from sim.cmdvel import Mismatch

        class Watch:
            seen = [Mismatch("ai_agent", "/cmd_vel", "geometry_msgs/msg/TwistStamped",
                             "geometry_msgs/msg/Twist")]

            def check(self):
                pass

        @pytest.fixture(scope="module", autouse=True)
        def watch(request):
            request.node.stash[type_watch_key] = Watch()

        @pytest.fixture(scope="module")
        def run():
            raise StudentFailure("the node never drove")

        def test_nothing_came():
            raise StudentFailure("nothing on cmd_vel", "publish it")

        def test_part_of_the_way(credit):
            credit.award(0.5, "half")

        def test_passes():
            pass

        def test_our_bug():
            raise RuntimeError("ours")

        def test_needs_the_run(run):
            pass
    ''')
    note = ("Your node 'ai_agent' publishes geometry_msgs/msg/TwistStamped on /cmd_vel, but "
            "this exercise's robot takes geometry_msgs/msg/Twist (its cmd_vel_type), so the "
            "robot never hears it: publish Twist.")
    assert tests["test_nothing_came"]["message"] == f"{note}\n\nnothing on cmd_vel"
    assert tests["test_nothing_came"]["hint"] == "publish it"
    assert tests["test_part_of_the_way"]["message"] == f"{note}\n\nhalf"
    assert tests["test_part_of_the_way"]["fraction"] == 0.5
    assert tests["test_needs_the_run"]["message"] == f"{note}\n\nthe node never drove"
    assert tests["test_passes"]["message"] == ""
    assert tests["test_our_bug"]["message"] == "RuntimeError: ours"


def test_a_teardown_failure_after_a_pass_is_classified(pytester: pytest.Pytester) -> None:
    """As the graph guard does: a fixture that finds tampering after the test fails it."""
    tests = grade_tests(pytester, '''
        import pytest
        from autograder.core.errors import StudentFailure

        @pytest.fixture
        def guard():
            yield
            raise StudentFailure("tampering seen", "publish only your topics")

        @pytest.fixture
        def broken_cleanup():
            yield
            raise RuntimeError("could not stop the world")

        def test_guarded(guard):
            pass

        def test_cleaned_up(broken_cleanup):
            pass

        def test_failed_then_guarded(guard):
            raise StudentFailure("wrong answer")
    ''')
    assert (tests["test_guarded"]["status"], tests["test_guarded"]["message"],
            tests["test_guarded"]["hint"]) == ("failed", "tampering seen",
                                               "publish only your topics")
    assert (tests["test_cleaned_up"]["status"], tests["test_cleaned_up"]["message"]) == (
        "error", "RuntimeError: could not stop the world")
    # The test's own failure is what it is reported with, not its teardown's.
    assert (tests["test_failed_then_guarded"]["status"],
            tests["test_failed_then_guarded"]["message"]) == ("failed", "wrong answer")


def test_a_setup_failure_is_the_students(pytester: pytest.Pytester) -> None:
    """As when the student's node never starts: the `student` fixture raises."""
    tests = grade_tests(pytester, '''
        import pytest
        from autograder.core.errors import StudentFailure

        @pytest.fixture
        def student():
            raise StudentFailure("no node named 'mini'", "create the node")

        def test_needs_node(student):
            pass
    ''')
    entry = tests["test_needs_node"]
    assert (entry["status"], entry["message"], entry["hint"]) == (
        "failed", "no node named 'mini'", "create the node")


def test_points_and_visibility_come_from_markers_and_folders(
        pytester: pytest.Pytester) -> None:
    tests = grade_tests(pytester, '''
        import pytest

        @pytest.mark.points(3)
        def test_worth_three():
            pass

        @pytest.mark.visibility("after_published")
        def test_shown_later():
            pass
    ''', '''
        import pytest

        def test_secret():
            pass

        @pytest.mark.visibility("visible")
        @pytest.mark.reveal("message")
        def test_open_secret():
            pass
    ''')
    assert tests["test_worth_three"]["max_score"] == 3
    assert tests["test_shown_later"]["max_score"] == 1
    assert (tests["test_worth_three"]["visibility"], tests["test_worth_three"]["reveal"]) == (
        "visible", "message")
    assert (tests["test_shown_later"]["visibility"], tests["test_shown_later"]["reveal"]) == (
        "after_published", "status")
    # Under tests/hidden/: the exercise's hidden_visibility, and only the status shown.
    assert (tests["test_secret"]["visibility"], tests["test_secret"]["reveal"]) == (
        "hidden", "status")
    assert (tests["test_open_secret"]["visibility"],
            tests["test_open_secret"]["reveal"]) == ("visible", "message")
    # exercise.yaml's core tests are marked, so the lines printed as tests end can say so.
    assert {name for name, t in tests.items() if t["core"]} == {"test_worth_three",
                                                                "test_secret"}


def test_a_public_run_counts_the_hidden_tests_without_running_them(
        pytester: pytest.Pytester) -> None:
    """What ``check`` says the grade adds: the hidden tests, counted with their points."""
    report = run_report(pytester, '''
        def test_public():
            pass
    ''', '''
        import pytest

        @pytest.mark.points(3)
        def test_secret():
            raise AssertionError("never run")

        def test_other_secret():
            raise AssertionError("never run")
    ''', count_hidden=True)
    assert [entry["name"] for entry in report["tests"]] == ["test_public"]
    assert report["tests"][0]["status"] == "passed"
    assert report["data"]["not_run"] == {"tests": 2, "points": "4"}


def test_a_test_that_never_ran_is_an_error_saying_so(pytester: pytest.Pytester) -> None:
    """A run that ends early (here at the first failure) leaves the rest as not run."""
    tests = grade_tests(pytester, '''
        def test_first():
            assert False, "first"

        def test_second():
            pass
    ''', "", "-x")
    assert tests["test_first"]["status"] == "failed"
    entry = tests["test_second"]
    assert (entry["status"], entry["done"]) == ("error", False)
    assert entry["message"].startswith("Not run")


def test_a_long_message_is_cut_to_a_few_kilobytes(pytester: pytest.Pytester) -> None:
    """Its start and its end, with a mark between (every results format repeats it)."""
    tests = grade_tests(pytester, '''
        from autograder.core.errors import StudentFailure

        def test_chatty():
            raise StudentFailure("start" + "x" * 1_000_000 + "end", "a short hint")
    ''')
    entry = tests["test_chatty"]
    message = entry["message"]
    assert message.startswith("start") and message.endswith("end")
    assert f"\n{CUT}\n" in message
    assert len(message.encode()) <= MESSAGE_BYTES + len(f"\n{CUT}\n".encode())
    assert entry["hint"] == "a short hint"  # short enough: kept whole
    # The traceback holds the message too: it is cut to its own, larger, budget.
    assert "x" * 1000 in entry["details"] and entry["details"].rstrip().endswith("end")
    assert len(entry["details"].encode()) <= DETAILS_BYTES + len(f"\n{CUT}\n".encode())


def test_without_exercise_the_plugin_writes_nothing(pytester: pytest.Pytester) -> None:
    """Inert unless an exercise is graded: the project's own suite runs beside it."""
    pytester.makepyfile("def test_plain():\n    pass\n")
    result = pytester.runpytest("-p", "no:cacheprovider")
    result.assert_outcomes(passed=1)
    assert not list(pytester.path.glob("*.json"))


def test_a_program_being_started_when_the_run_ends_is_recorded_before_the_reaping() -> None:
    """The lifeline's watcher reaps what ``ending()`` returns: a start in progress (inside
    the gate, from before its fork to its record) finishes first, so its program is among
    them; no program starts after (a killed grading left one running, issue 31)."""
    import threading

    from autograder.core.errors import GraderError
    from autograder.plugin.reporter import GradingReporter

    reporter = GradingReporter(None, None, b"")
    inside, go = threading.Event(), threading.Event()

    def start() -> None:
        with reporter.spawn_gate:
            inside.set()
            go.wait(30)
            reporter.note_process(4242, [], {})

    starter = threading.Thread(target=start)
    starter.start()
    assert inside.wait(30)
    records: list[list[dict[str, Any]]] = []
    closer = threading.Thread(target=lambda: records.append(reporter.ending()))
    closer.start()
    closer.join(0.2)  # an ungated ending returns here, before the program is recorded
    go.set()
    starter.join(30)
    closer.join(30)
    assert [r["pid"] for r in records[0]] == [4242]
    with pytest.raises(GraderError), reporter.spawn_gate:
        pass
