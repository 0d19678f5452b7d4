.PHONY: setup run test lint check bench

setup:
	bash scripts/setup.sh

run:
	bash scripts/run.sh

test:
	bash scripts/test.sh

lint: setup
	.venv/bin/ruff check galvo_core app tests bench
	.venv/bin/mypy

check: lint test

bench: setup
	bash bench/run_all.sh
