"""Pure renderers of a :class:`~autograder.results.RunResult`: one module per format."""
