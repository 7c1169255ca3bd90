"""The fixtures every test of autograder.core uses."""

from languages import english  # noqa: F401  (autouse: each test in English)
