"""Pure renderers of a :class:`~autograder.core.results.RunResult`: one module per format."""
