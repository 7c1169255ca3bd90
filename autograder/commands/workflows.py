"""CI templates for a course: a student repository's grade-on-push workflow, and sharded
batch grading on GitHub Actions (a matrix) or Kubernetes (an Indexed Job).

Secrets stay where students' programs are not: the student's workflow runs the public
tests and names none (students edit their own workflows); the course's token is used only
to fetch the course, in the course's own repository or a pod's init container, never where
a student's program runs. The Kubernetes Jobs meet Pod Security baseline.

Templates live in ``autograder/templates/ci``; their placeholders are ``[[ name ]]`` so
that GitHub's own ``${{ ... }}`` expressions pass through untouched.
"""

from __future__ import annotations

from typing import Any

import jinja2

TEMPLATES = {
    "github-student": "github-student.yml",
    "github-shards": "github-shards.yml",
    "k8s-shards": "k8s-shards.yml",
}

_ENV = jinja2.Environment(
    loader=jinja2.PackageLoader("autograder", "templates/ci"),
    variable_start_string="[[", variable_end_string="]]",
    block_start_string="[%", block_end_string="%]",
    autoescape=False, keep_trailing_newline=True, undefined=jinja2.StrictUndefined)


def render_workflow(kind: str, **values: Any) -> str:
    """The workflow ``kind`` with the course's values filled in."""
    return _ENV.get_template(TEMPLATES[kind]).render(**values)
