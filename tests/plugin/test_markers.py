"""The markers an exercise's tests carry: each well-formed one passes, and a malformed one
(a wrong value, none, or two) is named for the test's author, with what it should be."""

from __future__ import annotations

import pytest

from autograder.plugin.markers import MARKERS, marker_problem

TESTS = '''
    import pytest
    from fractions import Fraction

    pytestmark = [pytest.mark.world("corridor"), pytest.mark.parameters({"speed": 0.5})]

    @pytest.mark.points(3)
    @pytest.mark.visibility("after_published")
    @pytest.mark.reveal("status")
    def test_all_well_formed(): pass

    @pytest.mark.world("obstacle_course")
    def test_world_of_its_own(): pass

    @pytest.mark.parameters({"speed": 0.2})
    class TestParametersOfItsOwn:
        def test_in_it(self): pass

    @pytest.mark.points(0.5)
    def test_half_a_point(): pass

    @pytest.mark.points(Fraction(1, 3))
    def test_a_third(): pass

    def test_no_markers(): pass

    @pytest.mark.points(0)
    def test_zero_points(): pass

    @pytest.mark.points(-1.5)
    def test_negative_points(): pass

    @pytest.mark.points(True)
    def test_points_true(): pass

    @pytest.mark.points("2")
    def test_points_text(): pass

    @pytest.mark.points(1, 2)
    def test_two_points(): pass

    @pytest.mark.visibility("secret")
    def test_unknown_visibility(): pass

    @pytest.mark.visibility()
    def test_no_visibility(): pass

    @pytest.mark.reveal("everything")
    def test_unknown_reveal(): pass

    @pytest.mark.world("")
    def test_empty_world(): pass

    @pytest.mark.parameters(["speed", 0.5])
    def test_parameters_list(): pass

    @pytest.mark.points(2)
    class TestMarkedClass:
        def test_inherits(self): pass
'''


@pytest.fixture
def problems(pytester: pytest.Pytester) -> dict[str, str | None]:
    items = pytester.getitems(TESTS)
    return {item.name: marker_problem(item) for item in items}


def test_well_formed_markers_pass(problems):
    for name in ("test_all_well_formed", "test_half_a_point", "test_a_third",
                 "test_no_markers", "test_inherits"):
        assert problems[name] is None, name


@pytest.mark.parametrize(("name", "marker", "got"), [
    ("test_zero_points", "points", "(0,)"),
    ("test_negative_points", "points", "(-1.5,)"),
    ("test_points_true", "points", "(True,)"),
    ("test_points_text", "points", "('2',)"),
    ("test_two_points", "points", "(1, 2)"),
    ("test_unknown_visibility", "visibility", "('secret',)"),
    ("test_no_visibility", "visibility", "()"),
    ("test_unknown_reveal", "reveal", "('everything',)"),
    ("test_empty_world", "world", "('',)"),
    ("test_parameters_list", "parameters", "(['speed', 0.5],)"),
])
def test_a_malformed_marker_is_named_with_what_it_should_be(problems, name, marker, got):
    problem = problems[name]
    assert problem is not None, name
    assert f"::{name}: marker " in problem  # the test's node id first
    assert problem.endswith(f"marker {MARKERS[marker]}; got {got}")


@pytest.mark.parametrize(("name", "marker", "on"), [
    ("test_world_of_its_own", "world", "test_world_of_its_own"),
    ("test_in_it", "parameters", "TestParametersOfItsOwn"),
])
def test_a_module_marker_on_a_test_or_class_is_named_not_ignored(problems, name, marker, on):
    """The world and the student's parameters are the module's, started once for all its
    tests: on one test or class they would be silently unused."""
    assert problems[name] == (f"test_a_module_marker_on_a_test_or_class_is_named_not_ignored"
                              f".py::{'TestParametersOfItsOwn::' if on != name else ''}{name}"
                              f": marker {MARKERS[marker]}; found on {on!r}, where it would "
                              "not be used")


def test_every_marker_says_its_form():
    assert set(MARKERS) == {"points", "visibility", "world", "parameters", "reveal"}
    for name, text in MARKERS.items():
        assert text.startswith(f"{name}("), name
