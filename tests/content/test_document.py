"""Content files (content.document): YAML read with the line of every key and item, built
into dataclasses, each mistake a ContentError that reads ``file:line: field: message``."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Literal

import pytest

from content import ContentError, build, describe, load_document


@dataclasses.dataclass(frozen=True)
class Point:
    x: float
    y: float = 0.0


@dataclasses.dataclass(frozen=True)
class Shape:
    name: str = dataclasses.field(metadata={"doc": "What it is called."})
    kind: Literal["box", "ring"] = "box"
    corners: tuple[Point, ...] = ()
    size: tuple[float, float] = (1.0, 1.0)
    count: int = 1
    note: str | None = None

    def __post_init__(self) -> None:
        if self.count < 0:
            raise ValueError("count must not be negative")


TEXT = """\
name: crate
kind: ring
corners:
  - {x: 1, y: 2}
  - x: 3
size: [2, 0.5]
"""


def shape(text: str) -> Shape:
    doc = load_document("shape.yaml", text)
    return build(Shape, doc, doc.data)


def error_of(text: str) -> str:
    with pytest.raises(ContentError) as error:
        shape(text)
    return str(error.value)


def test_a_file_builds_its_dataclasses_lists_as_tuples() -> None:
    built = shape(TEXT)
    assert built == Shape("crate", "ring", (Point(1.0, 2.0), Point(3.0)), (2.0, 0.5))
    assert isinstance(built.corners[0].x, float)  # a whole number read as a float field


def test_every_key_and_item_has_its_line() -> None:
    doc = load_document("shape.yaml", TEXT)
    assert doc.line("name") == 1 and doc.line("corners") == 3
    assert doc.line("corners", 0) == 4 and doc.line("corners", 1, "x") == 5
    assert doc.line("corners", 1, "missing") == 5  # the nearest parent's
    assert doc.line("nothing") == 1


def test_an_item_is_named_by_its_id_where_it_has_one() -> None:
    doc = load_document("q.yaml", "questions:\n  - id: first\n    answer: 1\n  - answer: 2\n")
    assert doc.field("questions", 0, "answer") == "questions[first].answer"
    assert doc.field("questions", 1, "answer") == "questions.1.answer"
    assert str(doc.error("wrong", "questions", 0, "answer")) == \
        "q.yaml:3: questions[first].answer: wrong"


@pytest.mark.parametrize(("text", "expected"), [
    ("name: crate\nkind: cube\n",
     "shape.yaml:2: kind: must be one of 'box', 'ring', found 'cube'"),
    ("name: crate\ncount: 1.5\n", "shape.yaml:2: count: must be a whole number, found 1.5"),
    ("name: crate\ncount: true\n", "shape.yaml:2: count: must be a whole number, found True"),
    ("name: crate\nsize: [1]\n", "shape.yaml:2: size: must have 2 items, found 1"),
    ("name: crate\ncorners:\n  - {x: 1}\n  - {x: east}\n",
     "shape.yaml:4: corners.1.x: must be a number, found 'east'"),
    ("name: crate\ncorners: {x: 1}\n", "shape.yaml:2: corners: must be a list, found {'x': 1}"),
    ("kind: box\n", "shape.yaml:1: name: required field is missing"),
    ("name: crate\ncolour: red\n",
     "shape.yaml:2: colour: unknown field (expected one of: corners, count, kind, name, note, "
     "size)"),
    ("name: crate\nnote: 3\n", "shape.yaml:2: note: must be str, found 3"),
    ("name: crate\ncount: -1\n", "shape.yaml:1: count must not be negative"),
    ("- just\n- a list\n", "shape.yaml:1: must be a mapping, found ['just', 'a list']"),
], ids=["literal", "int", "bool-as-int", "tuple-length", "nested", "list", "required",
        "unknown", "optional", "post-init", "not-a-mapping"])
def test_each_mistake_names_file_line_and_field(text: str, expected: str) -> None:
    assert error_of(text) == expected


def test_the_yaml_itself_is_checked_with_its_line() -> None:
    assert error_of("name: crate\nname: box\n") == "shape.yaml:2: duplicate key 'name'"
    assert error_of("name: crate\n1: one\n") == "shape.yaml:2: keys must be text, found 1"
    assert error_of("name: [crate\n").startswith("shape.yaml:2: YAML error:")
    assert error_of("") == "shape.yaml:1: the file is empty"


def test_a_file_that_is_not_there_or_not_text_says_so(tmp_path: Path) -> None:
    with pytest.raises(ContentError, match=r"missing.yaml: file not found$"):
        load_document(tmp_path / "missing.yaml")
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(ContentError, match="binary.yaml: cannot read file"):
        load_document(binary)


def test_describe_lists_each_field_its_default_and_doc() -> None:
    rows = {name: (default, doc) for name, default, doc in describe(Shape)}
    assert rows["name"] == ("required", "What it is called.")
    assert rows["kind"] == ("'box'", "") and rows["corners"] == ("()", "")
