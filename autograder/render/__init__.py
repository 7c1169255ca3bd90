"""Pure renderers of a :class:`~autograder.core.results.RunResult`: one module per format.

Every module here that defines ``FORMAT`` (an :class:`OutputFormat`) is an output format:
``check`` and ``grade`` get its ``--NAME FILE`` option and ``grade-batch`` writes its
per-student file, with nothing else to change. To add a format, add one module with its
renderer and its ``FORMAT``.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
import pkgutil
from collections.abc import Callable
from pathlib import Path

from autograder.core.results import RunResult


@dataclasses.dataclass(frozen=True)
class OutputFormat:
    """A file a grading can be written as."""

    name: str  # the option: --NAME FILE
    help: str  # the option's help text
    render: Callable[[RunResult, Path], str]  # (result, the exercise's folder) -> text
    batch_file: str | None = None  # its name in grade-batch's folder per student
    order: int = 50  # where its option stands in --help


@functools.cache
def formats() -> dict[str, OutputFormat]:
    """Every output format, by option name, from the modules of this package."""
    found = []
    for module in pkgutil.iter_modules(__path__):
        declared = getattr(importlib.import_module(f"{__name__}.{module.name}"), "FORMAT", None)
        if isinstance(declared, OutputFormat):
            found.append(declared)
    return {f.name: f for f in sorted(found, key=lambda f: (f.order, f.name))}
