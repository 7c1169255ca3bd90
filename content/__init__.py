"""The course's content, below both the simulator and the autograder: where the course tree
is (:mod:`content.course`), its YAML files read with the line of every field
(:mod:`content.document`, one :class:`ContentError` naming ``file:line: field``), and the
gettext binding the simulator and these files speak through (:mod:`content.i18n`).

Nothing here imports ``sim`` or ``autograder``: both import this.
"""

from content.document import (
    ContentError,
    Document,
    FieldValueError,
    build,
    describe,
    load_document,
)

__all__ = ["ContentError", "Document", "FieldValueError", "build", "describe", "load_document"]
