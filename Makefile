# woodpile: every target calls the `woodpile` binary or cargo; `make help` lists them.
CARGO ?= cargo
WOODPILE = $(CARGO) run --quiet --release -p woodpile-cli --

.PHONY: help test figures bench scenes lint

help: ## List the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | awk 'BEGIN {FS = ":.*## "} {printf "  make %-10s %s\n", $$1, $$2}'

test: ## Run the whole test suite (what CI runs)
	$(CARGO) test --workspace

figures: ## PLACEHOLDER until the pipeline lands (issue 3): simulates the example scenes
	@echo "figures: PLACEHOLDER - the figure pipeline (issue 3) is not built yet."
	@echo "Simulating the example scenes in scenes/ instead:"
	@for f in scenes/*.toml; do echo "== $$f"; $(WOODPILE) simulate $$f || exit 1; done

scenes: figures ## Alias of the placeholder `figures`

bench: ## Error in E_tr against wall time for every method (README table)
	$(CARGO) run --release -p woodpile-sim --example work_precision

lint: ## rustfmt check and clippy with warnings as errors
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings
