"""Babel extractor for exercise test files: their ``_()`` messages and their labels.

A test's label is the first line of its docstring, translated when shown; Babel's Python
extractor reads calls, not docstrings, so this one yields both (Babel uses one method per
file).  Labels carry the comment "test label" for translators.
"""

from __future__ import annotations

import ast
import tokenize
from collections.abc import Collection, Iterator, Mapping
from typing import IO, Any

from babel.messages.extract import extract_python


def extract_tests(fileobj: IO[bytes], keywords: Mapping[str, Any],
                  comment_tags: Collection[str],
                  options: Mapping[str, Any]) -> Iterator[tuple[int, str, Any, list[str]]]:
    source = fileobj.read()
    fileobj.seek(0)
    try:
        yield from extract_python(fileobj, keywords, comment_tags, options)
    except tokenize.TokenError:  # an unclosed bracket: the calls before it, as pytest
        return                   # will say what is wrong with the file
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and \
                node.name.startswith("test_"):
            doc = ast.get_docstring(node)
            if doc and doc.strip():
                yield node.body[0].lineno, "_", doc.strip().splitlines()[0].strip(), \
                    ["test label"]
