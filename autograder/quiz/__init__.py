"""Quizzes: declarative files under ``quizzes/``, scored exactly, shown in English and Urdu.

Verbs live in their own modules: ``model`` (load and check a quiz file), ``shuffle``,
``scoring``, ``localize``, ``render`` (HTML, Markdown, terminal), ``lint``, ``server``
and ``cli``; ``extract`` is the Babel extractor for quiz and exercise files.
"""

CONTENT_DOMAIN = "content"
