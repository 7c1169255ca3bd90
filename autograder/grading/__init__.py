"""A grading run, seen from the grader: start the pytest child, collect its signed report."""
