"""The XML writer both exports build on (autograder.quiz.export.xml)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from autograder.quiz.export.xml import CData, el, to_xml


def test_writer_escapes_text_and_splits_cdata_that_holds_its_end() -> None:
    doc = to_xml(el("a", {"b": 'x"<'}, el("t", {}, "1 < 2 & 3"), el("h", {}, CData("x]]>y"))))
    root = ET.fromstring(doc)
    assert root.get("b") == 'x"<' and root.findtext("t") == "1 < 2 & 3"
    assert root.findtext("h") == "x]]>y"


def test_elements_are_indented_but_text_is_never_padded() -> None:
    doc = to_xml(el("quiz", {}, el("question", {"type": "x"}, el("text", {}, "Hi")),
                    el("p", {}, el("strong", {}, "bold")), el("empty")))
    assert doc == ('<?xml version="1.0" encoding="UTF-8"?>\n'
                   '<quiz>\n  <question type="x">\n    <text>Hi</text>\n  </question>\n'
                   '  <p><strong>bold</strong></p>\n  <empty/>\n</quiz>\n')


def test_mixed_content_stays_on_one_line() -> None:
    doc = to_xml(el("div", {}, "Press ", el("code", {}, "Ctrl-C"), " to stop."))
    assert doc.endswith("<div>Press <code>Ctrl-C</code> to stop.</div>\n")
    assert ET.fromstring(doc).findtext("code") == "Ctrl-C"


def test_none_attributes_and_empty_children_are_left_out() -> None:
    node = el("answer", {"fraction": "100", "format": None}, None, "", "yes")
    assert node.attrs == {"fraction": "100"} and node.children == ["yes"]
    assert to_xml(node).endswith('<answer fraction="100">yes</answer>\n')


def test_cdata_keeps_markup_as_text_through_a_parser() -> None:
    html = '<p dir="rtl">x ]]> y <b>&amp;</b></p>'
    doc = to_xml(el("text", {}, CData(html)))
    assert doc.count("<![CDATA[") == 2  # split at the ]]> it holds
    assert ET.fromstring(doc).text == html
