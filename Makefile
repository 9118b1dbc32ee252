# woodpile: every target calls the `woodpile` binary or cargo; `make help` lists them.
CARGO ?= cargo
WOODPILE := $(or $(CARGO_TARGET_DIR),target)/release/woodpile
# Regression check: recompute every stage from nothing into SCRATCH and compare with results/.
SCRATCH := scratch/check
# Wall times (work-precision stages) belong to the machine that measured them: not compared.
CHECK_TOL := --abs 1e-9 --rel 1e-9 --tol wall_ms=inf --tol log10_wall_ms=inf

.PHONY: help build install audit test rust-test python python-test wheel wheel-test python-bench docs figures stage status check read-check bench unused-cost work-precision lint old-cpu-test slurm-test

help: ## List the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk 'BEGIN {FS = ":.*## "} {printf "  make %-11s %s\n", $$1, $$2}'

build: ## Build the woodpile binary (release)
	$(CARGO) build --release -p woodpile-cli

install: ## Put `woodpile` on the PATH (cargo install into ~/.cargo/bin, reusing this build)
	$(CARGO) install --locked --path crates/woodpile-cli --target-dir $(or $(CARGO_TARGET_DIR),target)

# The Python package's own virtual environment (python-test builds it the README's way).
VENV := .venv
PY := $(VENV)/bin/python

python: ## Install the Python package into .venv, as the README says (pip install ./python)
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check ./python

# The package is installed as `make python` installs it, plus the test-only entry points
# (the Python crate's feature `testing`), which the wheel and `pip install ./python` leave out.
python-test: build ## The Python package's tests and the quickstart notebook, in .venv (Pipeline drives this clone's woodpile)
	test -x $(PY) || python3 -m venv $(VENV)
	MATURIN_PEP517_ARGS="--features testing" $(PY) -m pip install --quiet --disable-pip-version-check ./python
	$(PY) -m pip install --quiet --disable-pip-version-check pytest matplotlib nbclient nbformat ipykernel scipy
	WOODPILE_BIN=$(abspath $(WOODPILE)) $(PY) -m pytest -q -p no:cacheprovider python/tests
	WOODPILE_BIN=$(abspath $(WOODPILE)) $(PY) scripts/run_notebook.py examples/quickstart.ipynb

# The wheel: the native module and the `woodpile` command in one abi3 wheel, installable with
# no Rust toolchain. Tested in its own venv, with cargo off the PATH.
WHEEL_VENV := .wheel-venv
NO_CARGO_PATH = $(shell python3 -c 'import os; print(os.pathsep.join(d for d in os.environ["PATH"].split(os.pathsep) if not os.path.exists(os.path.join(d, "cargo"))))')

wheel: build ## Build dist/woodpile-*.whl: the native module and the woodpile command (abi3, Python >= 3.9)
	test -x $(PY) || python3 -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check "maturin>=1.9,<2"
	rm -rf dist python/woodpile/bin
	mkdir -p python/woodpile/bin
	cp $(WOODPILE) python/woodpile/bin/woodpile
	strip python/woodpile/bin/woodpile 2>/dev/null || true
	$(VENV)/bin/maturin build --release --strip --out dist -m python/Cargo.toml; status=$$?; rm -rf python/woodpile/bin; exit $$status

wheel-test: wheel ## Install the wheel into a fresh venv with no cargo on the PATH; its woodpile command, the Python tests and the notebook there
	rm -rf $(WHEEL_VENV)
	python3 -m venv $(WHEEL_VENV)
	$(WHEEL_VENV)/bin/pip install --quiet --disable-pip-version-check "$$(ls dist/woodpile-*.whl)[notebook]" pytest nbclient nbformat
	env -u WOODPILE_BIN WOODPILE_TEST_INSTALLED=1 PATH="$(abspath $(WHEEL_VENV))/bin:$(NO_CARGO_PATH)" /bin/sh -ec '\
	  if command -v cargo; then echo "cargo is still on the PATH" >&2; exit 1; fi; \
	  woodpile --version; \
	  python -m pytest -q -p no:cacheprovider python/tests; \
	  python scripts/run_notebook.py examples/quickstart.ipynb'

python-bench: python build ## woodpile.simulate and woodpile.sweep against the Rust calls (docs/performance.md)
	WOODPILE_BIN=$(abspath $(WOODPILE)) $(PY) python/benches/bench.py

docs: ## Regenerate docs/stage-kinds.md and the README's accuracy captions
	UPDATE_DOCS=1 $(CARGO) test --release -p woodpile-stages -p woodpile-cli --test docs

test: rust-test python-test ## Run the whole test suite: Rust, then Python (what CI runs)

rust-test: ## The Rust tests (release profile, shared with `figures`), and the bench's independent reference's
	$(CARGO) test --workspace --release --exclude woodpile-bench --exclude woodpile-py
	$(CARGO) test --release -p woodpile-bench --test independent_reference

figures: build ## Bring every stale stage up to date (nothing runs when all are fresh)
	$(WOODPILE) run

stage: build ## Re-run one stage, even when fresh (stale inputs first): make stage S=f4_fractions
	@test -n "$(S)" || { echo "usage: make stage S=<stage name>  (see: make status)"; exit 2; }
	$(WOODPILE) run $(S) --force

status: build ## Each stage fresh, stale or missing, and why
	$(WOODPILE) status

check: build ## Recompute every stage into scratch/ and diff against the committed results/
	$(WOODPILE) status --check
	rm -rf $(SCRATCH)
	$(WOODPILE) run --results $(SCRATCH)/results --figures $(SCRATCH)/figures
	$(WOODPILE) diff results $(SCRATCH)/results $(CHECK_TOL)

read-check: ## Open every result table with pyarrow, pandas and polars
	python3 scripts/read_results.py results

BASELINE := $(or $(CARGO_TARGET_DIR),target)/baseline

bench: build ## Speed (PREVIOUS=old/woodpile adds it, same run): woodpile against the C and numba RK4 baselines in one run (standard scene, paper sample, the five sweeps whole, the whole paper cold), batched against scalar scenes, damped against undamped
	mkdir -p $(BASELINE)
	gcc -O3 -march=x86-64-v3 -o $(BASELINE)/rk4_chain baseline/rk4_chain.c -lm
	python3 -c 'import numba' 2>/dev/null || python3 -m pip install --quiet --disable-pip-version-check numba
	$(CARGO) run --release -q -p woodpile-bench -- --c $(BASELINE)/rk4_chain --numba baseline/rk4_numba.py --numba-scenes baseline/rk4_numba_scenes.py --sweeps --whole-paper
	$(CARGO) run --release -q -p woodpile-bench --example batch_lanes -- 16 0.215
	$(CARGO) run --release -q -p woodpile-bench --example damped_cost -- 1e-8,1e-10,1e-11
	$(MAKE) --no-print-directory unused-cost
	@if [ -n "$(PREVIOUS)" ]; then \
	  echo "this build against the previous release build $(PREVIOUS):"; \
	  $(CARGO) run --release -q -p woodpile-bench --example unused_cost -- $(PREVIOUS) $(WOODPILE) 15 --numbers-may-differ; \
	fi
	$(CARGO) bench -p woodpile-bench

# The last commit before dissipation (dashpots, ground damping, soft ends, the energy ledger).
COST_BASE := e37d8ad
OLD_TARGET := $(abspath $(or $(CARGO_TARGET_DIR),target))/old

unused-cost: build ## What features a scene does not use cost it: COST_BASE's binary against this one
	rm -rf $(BASELINE)/old-src && mkdir -p $(BASELINE)/old-src
	git archive $(COST_BASE) | tar -x -C $(BASELINE)/old-src
	cd $(BASELINE)/old-src && CARGO_TARGET_DIR=$(OLD_TARGET) $(CARGO) build --release -q -p woodpile-cli
	$(CARGO) run --release -q -p woodpile-bench --example unused_cost -- $(OLD_TARGET)/release/woodpile $(WOODPILE)

audit: ## auto against an independent reference: 200 random scenes at 1e-5..1e-8, the same with linear resonators only, 100 of the experiment's chain, 100 with damping, 100 with linear losses only, 100 standing in gravity, 100 with gapped linear contacts; and scenes in SIMD lanes against their scalar runs
	$(CARGO) run --release -q -p woodpile-bench --example auto_audit -- 200 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example auto_audit -- --linear 200 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example auto_audit -- --chain 100 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example auto_audit -- --damped 100 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example auto_audit -- --linear-losses 100 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example auto_audit -- --gravity 100 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example auto_audit -- --gap 100 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example lanes_audit -- 100 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example lanes_audit -- --chain 40 2026 1e-5,1e-6,1e-7,1e-8
	$(CARGO) run --release -q -p woodpile-bench --example lanes_audit -- --gap 40 2026 1e-5,1e-6,1e-7,1e-8

work-precision: ## Error in E_tr against wall time for every method and step (README table)
	$(CARGO) run --release -p woodpile-sim --example work_precision

lint: ## rustfmt check and clippy with warnings as errors
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

old-cpu-test: build ## The binary on an emulated CPU without AVX2 (QEMU Nehalem; installs qemu-user): same numbers
	WOODPILE=$(WOODPILE) bash scripts/old_cpu_test.sh

slurm-test: build ## Sharded sweep on a real one-node SLURM cluster (installs slurm-wlm, munge), diffed against a local run
	bash scripts/slurm-test/run.sh
