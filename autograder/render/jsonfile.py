"""Our JSON results file (``--results``)."""

from __future__ import annotations

import json

from autograder.core.results import RunResult
from autograder.render import OutputFormat


def to_json(result: RunResult) -> str:
    return json.dumps(result.to_dict(), ensure_ascii=False, indent=2) + "\n"


FORMAT = OutputFormat(
    "results", "Write the results as JSON to this file (the programs' whole output goes "
    "beside it, as FILE with suffix .log).", lambda result, _folder: to_json(result),
    batch_file="results.json", order=10)
