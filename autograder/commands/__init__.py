"""The course-level commands behind the CLI: batch grading, releases, validation, CI
workflows, gradebooks."""
