"""The question types, by the name a quiz file gives in ``type:``: the one registry.

Each module of this package defines one type (a :class:`~.base.QuestionType` subclass)
and adds it with ``@register``; the generic quiz modules (model, scoring, shuffle, render,
server, cli, lint) look a question's type up here and never branch on its name.

The modules are imported on the first lookup, not when this package is imported: they
build on ``model``, ``views`` and ``shuffle``, which themselves look types up here.
"""

from __future__ import annotations

import importlib
import pkgutil
from typing import TYPE_CHECKING, TypeVar

if TYPE_CHECKING:
    from autograder.quiz.types.base import QuestionType

T = TypeVar("T", bound="type[QuestionType]")

_REGISTRY: dict[str, QuestionType] = {}
_SUPPORT_MODULES = frozenset({"base"})  # modules here that define no type
_loaded = False


def register(cls: T) -> T:
    """Class decorator: make ``cls`` the question type named ``cls.name``."""
    _REGISTRY[cls.name] = cls()
    return cls


def registry() -> dict[str, QuestionType]:
    """Every question type by name (tests may add one with ``monkeypatch.setitem``)."""
    global _loaded
    if not _loaded:
        _loaded = True
        for info in pkgutil.iter_modules(__path__):
            if info.name not in _SUPPORT_MODULES and not info.name.startswith("_"):
                importlib.import_module(f"{__name__}.{info.name}")
    return _REGISTRY


def question_type(name: str) -> QuestionType:
    """The type called ``name``; a quiz that loaded only has names in the registry."""
    return registry()[name]
