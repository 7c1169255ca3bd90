"""Quizzes: declarative files under ``quizzes/``, scored exactly, shown in English and Urdu.

Verbs live in their own modules: ``model`` (load and check a quiz file), ``shuffle``,
``scoring``, ``localize``, ``views`` (what a student sees), ``render`` (HTML, Markdown),
``lint``, ``server`` and ``cli``; ``extract`` is the Babel extractor for quiz and exercise
files.  What differs between question types lives in ``types``, one module per type.
"""

CONTENT_DOMAIN = "content"
