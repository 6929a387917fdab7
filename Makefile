# The README's commands. `make test` is what CI runs (via .ci/run).
CARGO ?= cargo
export CARGO
# The viewer's scene: `make viewer SCENE=menger`.
SCENE ?= fractal_mix

.PHONY: setup demo test bench viewer snapshots golden fmt mutants

setup:
	@echo "==> setup: system packages"
	@bash scripts/setup.sh

demo: setup
	@echo "==> demo: $(CARGO) run --release --example gallery"
	$(CARGO) run --release --example gallery
	$(CARGO) run --release --example keyframes

test: setup
	@bash scripts/test.sh

viewer: setup
	$(CARGO) run --release --features viewer --example viewer -- $(SCENE)

# How many deliberate bugs the tests catch (not part of `make test`).
mutants: setup
	@bash scripts/mutants.sh

bench:
	@echo "==> bench"
	$(CARGO) bench

snapshots:
	@echo "==> snapshots: regenerating codegen snapshots"
	UPDATE_SNAPSHOTS=1 $(CARGO) test --test kernel snapshots

fmt:
	$(CARGO) fmt --all

golden:
	@echo "==> golden: regenerating golden render images"
	UPDATE_GOLDEN=1 $(CARGO) test --test render golden
