"""The dev container (macOS and Windows students' way to the same commands, issue 35) is
valid against the Dev Container spec's schema and installs as CI does: the same Debian
packages script, then tasks.py."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = json.loads((ROOT / "tests" / "schemas" / "devContainer.base.schema.json").read_text())
DEFINITION = ROOT / ".devcontainer" / "devcontainer.json"


def _validator() -> jsonschema.protocols.Validator:
    cls = jsonschema.validators.validator_for(SCHEMA)
    cls.check_schema(SCHEMA)
    return cls(SCHEMA)


def test_the_definition_is_valid_against_the_spec_schema() -> None:
    errors = [e.message for e in _validator().iter_errors(json.loads(DEFINITION.read_text()))]
    assert not errors, errors


@pytest.mark.parametrize("broken", [{"image": 3}, {"image": "debian", "forwardPorts": "8765"},
                                    {"image": "debian", "onCreateCommand": 7}],
                         ids=["image-not-a-string", "ports-not-a-list", "command-not-a-string"])
def test_the_schema_refuses_a_broken_definition(broken: dict) -> None:
    assert list(_validator().iter_errors(broken))


def test_it_installs_as_ci_does() -> None:
    definition = json.loads(DEFINITION.read_text())
    command = definition["onCreateCommand"]
    assert "bash .ci/system-packages" in command and "python3 tasks.py " in command
    assert "bash .ci/system-packages" in (ROOT / ".ci" / "run").read_text()
    # Its terminals find `autograder` with no activation.
    assert definition["remoteEnv"]["PATH"].startswith("${containerWorkspaceFolder}/.venv/bin:")
