"""``python -m autograder``: the ``autograder`` command, for a checkout without the script."""

from autograder.cli import main

if __name__ == "__main__":
    main(prog_name="autograder")
