"""``python -m autograder.cli``: the ``autograder`` command."""

from autograder.cli import main

main()
