# The README's two set-up commands: `make demo` and `make test`.
# Each installs what it needs (Debian and PyPI packages, then this package).
PYTHON ?= python3
export PYTHON

.PHONY: demo test install deps bench

demo: install
	$(PYTHON) examples/demo.py

test: install
	$(PYTHON) -m pytest -q tests

install: deps
	bash scripts/dev-install.sh

deps:
	bash scripts/install-deps.sh
