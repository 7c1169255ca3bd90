"""Our JSON results file (``--results``)."""

from __future__ import annotations

import json

from autograder.core.results import RunResult


def to_json(result: RunResult) -> str:
    return json.dumps(result.to_dict(), ensure_ascii=False, indent=2) + "\n"
