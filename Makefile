# Thin wrappers: every job lives in tasks.py, which needs only Python 3.10+.
PYTHON ?= python3
.PHONY: demo test lint bench
demo test lint bench:
	$(PYTHON) tasks.py $@
