"""``autograder quiz export``: quizzes for a learning management system.

``moodle`` writes one Moodle XML file carrying every language in multilang spans;
``qti`` writes an IMS QTI 2.1 content package in one language.  Each question type
builds its own question with the builders of these modules
(``QuestionType.moodle_question``, ``QuestionType.qti_item``).
"""

from autograder.quiz.export.common import FORMATS
from autograder.quiz.export.moodle import export_moodle_xml
from autograder.quiz.export.qti import export_qti

__all__ = ["FORMATS", "export_moodle_xml", "export_qti"]
