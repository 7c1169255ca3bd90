"""The ``autograder`` command: a thin click layer over plain functions."""

from __future__ import annotations

import click

from autograder import __version__
from autograder.i18n import LANGUAGES, set_language


@click.group()
@click.version_option(__version__, prog_name="autograder")
@click.option("--lang", type=click.Choice(LANGUAGES), default=None, envvar="AUTOGRADER_LANG",
              help="Language of what the platform prints (en, ur).")
def main(lang: str | None) -> None:
    """Grade rclpy exercises in a simulated ROS 2 world, and take quizzes."""
    if lang:
        set_language(lang)
