# The two commands a new user runs are `make demo` and `make test`; both install what is missing first.
SHELL := /bin/bash
.DEFAULT_GOAL := help
VENV := .venv
PY := $(VENV)/bin/python
CARGO ?= cargo
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
APT_PACKAGES := pkg-config clang libclang-dev libavcodec-dev libavformat-dev libavutil-dev \
	libswscale-dev libswresample-dev libavfilter-dev libavdevice-dev python3-venv openimageio-tools time \
	fonts-dejavu-core
PY_PACKAGES := pymeshlab DracoPy numpy zstandard

.PHONY: help deps apt-deps venv demo test bench fuzz clean

help:
	@echo "make demo   encode a sample animation both ways and print size and error"
	@echo "make test   format check, clippy, all tests"
	@echo "make bench  rate-distortion and speed tables and plots (bench-out/)"
	@echo "make deps   install Debian packages and the reference-tool virtualenv (done by demo/test)"

deps: apt-deps venv

# Skipped when every package is already installed; apt-get update only when something is missing.
apt-deps:
	@missing=$$(for p in $(APT_PACKAGES); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
		echo "installing: $$missing"; \
		$(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing >/dev/null; \
	fi

venv: $(VENV)/.done

# Re-run when the Makefile (and so PY_PACKAGES) changes; pip skips what is already installed.
$(VENV)/.done: Makefile
	python3 -m venv $(VENV)
	$(VENV)/bin/pip install -q --disable-pip-version-check $(PY_PACKAGES)
	touch $@

demo: deps
	$(CARGO) build --release --quiet
	bash scripts/demo.sh

test: deps
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets --quiet -- -D warnings
	MCGV_PYTHON=$(abspath $(PY)) $(CARGO) test --workspace --quiet

bench: deps
	$(CARGO) build --release --quiet
	MCGV_PYTHON=$(abspath $(PY)) bash scripts/bench.sh

clean:
	$(CARGO) clean
	rm -rf $(VENV) bench-out demo-out
