# The two commands a new user runs are `make demo` and `make test`; both install what is missing first.
SHELL := /bin/bash
.DEFAULT_GOAL := help
VENV := .venv
PY := $(VENV)/bin/python
CARGO ?= cargo
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
# chromium: the browser test (cli/tests/cli/browser.rs) draws glTF files in it, headless.
APT_PACKAGES := pkg-config clang libclang-dev libavcodec-dev libavformat-dev libavutil-dev \
	libswscale-dev libswresample-dev libavfilter-dev libavdevice-dev python3-venv openimageio-tools time \
	fonts-dejavu-core chromium
PY_PACKAGES := pymeshlab DracoPy numpy zstandard constriction brotli
# Node tools of the bench's glTF peers (gltfpack, @gltf-transform, meshoptimizer) and of the tests
# (gltf-validator, three), pinned by its lockfile.
NODE_DIR := scripts/node

.PHONY: help deps apt-deps venv node-deps demo test bench fuzz install clean
PREFIX ?= /usr/local

help:
	@echo "make demo   encode a sample animation both ways and print size and error"
	@echo "make test   format check, clippy, all tests"
	@echo "make bench  rate-distortion and speed tables and plots (bench-out/)"
	@echo "make fuzz   fuzz the stream decoder and the mesh readers, FUZZ_SECONDS (default 300) each"
	@echo "make install  the binary, shell completions and man pages under PREFIX (default /usr/local); needs only cargo"
	@echo "make deps   install Debian packages, the reference-tool virtualenv and the bench's Node tools (done by demo/test)"

deps: apt-deps venv node-deps

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

# Debian's nodejs and npm only when there is no node at all; then the lockfile's packages into
# scripts/node/node_modules (npm ci), again only when package.json or the lockfile changed.
node-deps: $(NODE_DIR)/node_modules/.done

$(NODE_DIR)/node_modules/.done: $(NODE_DIR)/package.json $(NODE_DIR)/package-lock.json
	@command -v node >/dev/null && command -v npm >/dev/null || { \
		$(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq nodejs npm >/dev/null; }
	cd $(NODE_DIR) && npm ci --no-audit --no-fund --loglevel=error
	touch $@

demo: deps
	$(CARGO) build --release --quiet
	bash scripts/demo.sh

# The second clippy builds the library and the binary alone, as a user does: without the
# `internals` feature the tests turn on, so an internal item used only by tests is dead code there,
# and the CLI cannot reach past the library's public API. The docs must build without a warning.
test: deps
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets --quiet -- -D warnings
	$(CARGO) clippy --workspace --lib --bins --quiet -- -D warnings
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --no-deps -p mcgv-video --quiet
	MCGV_PYTHON=$(abspath $(PY)) $(CARGO) test --workspace --quiet
	$(PY) scripts/test_peers.py

bench: deps
	$(CARGO) build --release --quiet
	MCGV_PYTHON=$(abspath $(PY)) bash scripts/bench.sh

# libFuzzer through cargo-fuzz: a nightly toolchain when there is one (with AddressSanitizer), else the
# stable compiler unlocked by RUSTC_BOOTSTRAP and no sanitizer (safe Rust needs none to find panics).
# Seeds are small real streams and meshes made from media/; new inputs libFuzzer finds accumulate in
# fuzz/corpus/TARGET, crashers land in fuzz/artifacts/TARGET (replay them with tests/it/fuzz_regressions.rs).
# One process per target, overflow checks on, 10 s per input at most, 2 GB of memory at most.
FUZZ_SECONDS ?= 300
FUZZ_TARGETS ?= decode_stream read_mesh
HAVE_NIGHTLY := $(shell rustup run nightly rustc --version >/dev/null 2>&1 && echo yes)
ifeq ($(HAVE_NIGHTLY),yes)
FUZZ_CARGO := $(CARGO) +nightly
FUZZ_SANITIZER ?= address
else
FUZZ_CARGO := RUSTC_BOOTSTRAP=1 $(CARGO)
FUZZ_SANITIZER ?= none
endif

fuzz: apt-deps
	@command -v cargo-fuzz >/dev/null || $(CARGO) install cargo-fuzz --locked
	$(CARGO) build --quiet
	bash scripts/fuzz_seeds.sh target/debug/mcgv-video fuzz/seeds >/dev/null
	@mkdir -p fuzz/logs; status=0; \
	for t in $(FUZZ_TARGETS); do \
		mkdir -p fuzz/corpus/$$t; \
		echo "fuzzing $$t for $(FUZZ_SECONDS) s (log: fuzz/logs/$$t.log)"; \
		$(FUZZ_CARGO) fuzz run --fuzz-dir fuzz -s $(FUZZ_SANITIZER) --debug-assertions $$t \
			fuzz/corpus/$$t fuzz/seeds/$$t -- -max_total_time=$(FUZZ_SECONDS) -timeout=10 \
			-rss_limit_mb=2048 -print_final_stats=1 >fuzz/logs/$$t.log 2>&1 || status=1; \
		grep -E "^(Done|stat::number_of_executed_units)|SUMMARY|panicked|deadly signal|out-of-memory|timeout" \
			fuzz/logs/$$t.log | head -5; \
	done; \
	exit $$status

# The binary (the `dist` profile: release, stripped, no debug information), its completions and
# a man page per command, under PREFIX. Needs cargo and nothing else: no test dependency is
# installed. The completions and man pages come from the binary itself (clap_complete,
# clap_mangen), so they always match its flags. DESTDIR for staged installs (packaging);
# CARGO_FLAGS=--no-default-features builds without FFmpeg (JPEG and tdct only, no shared
# libraries needed at run time).
MAN_PAGES := encode decode inspect eval info convert completions man
CARGO_FLAGS ?=

install:
	@$(CARGO) build --profile dist --quiet -p mcgv-video-cli $(CARGO_FLAGS) || { \
		echo "the default build links FFmpeg: install its development packages and clang"; \
		echo "(make apt-deps), or build without it: make install CARGO_FLAGS=--no-default-features"; \
		exit 1; }
	@bin=target/dist/mcgv-video; dest=$(DESTDIR)$(PREFIX); share=$$dest/share; \
	install -Dm755 $$bin $$dest/bin/mcgv-video && \
	mkdir -p $$share/bash-completion/completions $$share/zsh/site-functions \
		$$share/fish/vendor_completions.d $$share/man/man1 && \
	$$bin completions bash >$$share/bash-completion/completions/mcgv-video && \
	$$bin completions zsh >$$share/zsh/site-functions/_mcgv-video && \
	$$bin completions fish >$$share/fish/vendor_completions.d/mcgv-video.fish && \
	$$bin man >$$share/man/man1/mcgv-video.1 && \
	for page in $(MAN_PAGES); do \
		$$bin man $$page >$$share/man/man1/mcgv-video-$$page.1 || exit 1; \
	done && \
	echo "installed $$dest/bin/mcgv-video ($$(du -k $$bin | cut -f1) KB), its completions and man pages" && \
	libs=$$(ldd $$bin 2>/dev/null | grep -oE 'lib(av|sw|postproc)[a-z]*\.so[.0-9]*' | sort -u | tr '\n' ' '); \
	echo "shared libraries it needs at run time besides the C library: $${libs:-none}"

clean:
	$(CARGO) clean
	rm -rf $(VENV) bench-out demo-out $(NODE_DIR)/node_modules
