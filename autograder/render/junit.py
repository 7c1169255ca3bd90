"""JUnit XML, which every CI system reads: one testcase per test, failures with messages."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from autograder.core.results import RunResult, number
from autograder.core.untrusted import visible
from autograder.render import OutputFormat
from autograder.render.verdict import core_label, core_note


def to_junit(result: RunResult) -> str:
    failures = sum(t.status == "failed" for t in result.tests)
    errors = sum(t.status == "error" for t in result.tests)
    skipped = sum(t.status == "skipped" for t in result.tests)
    suites = ET.Element("testsuites")
    suite = ET.SubElement(suites, "testsuite", {
        "name": f"{result.kind}.{result.id}", "tests": str(len(result.tests)),
        "failures": str(failures), "errors": str(errors), "skipped": str(skipped),
        "time": f"{result.execution_time:.3f}",
    })
    properties = ET.SubElement(suite, "properties")
    # A partial run (check) has no verdict: it says it is partial instead of "passed".
    verdict = ("passed", str(result.passed).lower()) if result.complete else \
        ("complete", "false")
    for name, value in (("score", number(result.score)), ("max_score", number(result.max_score)),
                        verdict, ("pass_mark", number(result.pass_mark)),
                        ("core_missed", " ".join(t.name for t in result.core_missed)),
                        ("lang", result.lang)):
        ET.SubElement(properties, "property", {"name": name, "value": str(value)})
    for test in result.tests:
        case = ET.SubElement(suite, "testcase", {
            "classname": f"{result.id}.{test.visibility}", "name": test.name,
            "time": "0"})
        ET.SubElement(case, "properties").extend([
            ET.Element("property", {"name": "label", "value": core_label(test)}),
            ET.Element("property", {"name": "core", "value": str(test.core).lower()}),
            ET.Element("property", {"name": "score", "value": str(number(test.score))}),
            ET.Element("property", {"name": "max_score", "value": str(number(test.max_score))}),
        ])
        text = "\n".join(p for p in (test.message, test.hint,
                                     core_note() if test.core else "") if p)
        if test.status == "failed":
            ET.SubElement(case, "failure", {"message": _first_line(test.message)}).text = text
        elif test.status == "error":
            ET.SubElement(case, "error", {"message": test.message}).text = test.details or text
        elif test.status == "skipped":
            ET.SubElement(case, "skipped", {"message": test.message})
    if result.grader_error:
        ET.SubElement(suite, "system-err").text = result.grader_details
    if result.log_tail:
        ET.SubElement(suite, "system-out").text = result.log_tail
    _well_formed(suites)
    ET.indent(suites)
    return ET.tostring(suites, encoding="unicode", xml_declaration=True) + "\n"


def _well_formed(root: ET.Element) -> None:
    """Every text and attribute under ``root`` as :func:`visible` shows it: the results
    model holds such text already, but a CI reporter that meets one NUL or ESC in the file
    gives up on the whole student, so nothing that reaches this file goes unchecked."""
    for element in root.iter():
        if element.text:
            element.text = visible(element.text)
        for name, value in element.attrib.items():
            element.attrib[name] = visible(value)


def _first_line(message: str) -> str:
    """A message's first line for an attribute, marked when more follows (a line ending
    "Its last lines:" must not read as if nothing came after it)."""
    lines = message.strip().splitlines()
    return lines[0] + (" …" if len(lines) > 1 else "") if lines else ""


FORMAT = OutputFormat(
    "junit", "Write JUnit XML to this file.", lambda result, _folder: to_junit(result),
    order=40)
