"""``autograder quiz export``: quizzes for a learning management system.

``moodle`` writes one Moodle XML file carrying every language in multilang spans.  Each
question type builds its own question with the builders of that module
(``QuestionType.moodle_question``).
"""

from autograder.quiz.export.common import FORMATS
from autograder.quiz.export.moodle import export_moodle_xml

__all__ = ["FORMATS", "export_moodle_xml"]
