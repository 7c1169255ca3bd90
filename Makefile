# Thin wrappers: every job lives in tasks.py, which needs only Python 3.10+.
PYTHON ?= python3
.PHONY: setup demo test test-all lint bench bench-ci
setup demo test test-all lint bench bench-ci:
	$(PYTHON) tasks.py $@
