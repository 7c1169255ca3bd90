"""Where the plugin keeps its state on pytest's config and items: a key of its own for each
thing (one shared would hand a test's credit to its evidence), filled by a grading run and
left empty by a plain pytest run."""

from __future__ import annotations

import textwrap

import pytest

from autograder.core.settings import RunSettings
from autograder.plugin import stash

KEYS = ("settings_key", "reporter_key", "credit_key", "evidence_key", "type_watch_key",
        "world_key", "startup_key")


def test_each_thing_has_a_key_of_its_own():
    keys = [getattr(stash, name) for name in KEYS]
    assert all(isinstance(key, pytest.StashKey) for key in keys)
    assert len({id(key) for key in keys}) == len(KEYS)
    # Every key of the module is listed here (a new one gets its test too).
    assert {name for name, value in vars(stash).items()
            if isinstance(value, pytest.StashKey)} == set(KEYS)
    held = pytest.Stash()
    held[stash.credit_key] = "credit"
    assert stash.evidence_key not in held


INNER = '''
    from autograder.plugin.reporter import GradingReporter
    from autograder.plugin.stash import reporter_key, settings_key, startup_key, world_key

    def test_state(request):
        config = request.config
        if {grading!r}:
            assert config.stash[settings_key].exercise == {exercise!r}
            assert isinstance(config.stash[reporter_key], GradingReporter)
        else:
            assert settings_key not in config.stash and reporter_key not in config.stash
        assert startup_key not in config.stash  # no student started yet
        assert config.stash.get(world_key, None) is None  # no world outside a module's
'''


@pytest.mark.parametrize("grading", [True, False])
def test_a_grading_run_keeps_its_settings_and_reporter(pytester: pytest.Pytester,
                                                       grading: bool) -> None:
    folder = pytester.path / "mini"
    (folder / "tests").mkdir(parents=True)
    (folder / "exercise.yaml").write_text(
        "id: mini\ntitle: Mini\nfile: mini.py\nnode: mini\n")
    test = folder / "tests" / "test_inner.py"
    test.write_text(textwrap.dedent(
        INNER.format(grading=grading, exercise=str(folder))))
    settings = RunSettings(exercise=str(folder), report=str(pytester.path / "report.json"))
    args = ["--autograder-settings", settings.to_json()] if grading else []
    pytester.runpytest("-p", "no:cacheprovider", *args, str(test)).assert_outcomes(passed=1)
    assert (pytester.path / "report.json").exists() == grading
