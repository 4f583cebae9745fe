# langevin-fem — build, verify, test.
#
#   make verify            quick verification suite (CI), reports in reports/
#   make verify BUDGET=full   publication-grade error bars
#   make test              all tests (unit, integration, statistical validation, golden)
#   make check             fmt --check, clippy -D warnings, tests
#   make bench             benchmarks (benches/), see README performance table
#   make golden            re-run golden snapshots, accept changes, show the diff
#   make fig2              the paper's Fig. 2 (compression scenes, full budget)
#   make converge          convergence studies (orders in h and dt), reports/convergence/

CARGO  ?= cargo
BUDGET ?= quick
OUT    ?= reports
BIN     = target/release/langevin-fem

.PHONY: all build verify test check bench golden clean fig2 converge

all: build

build:
	$(CARGO) build --release --locked

verify: build
	$(BIN) verify --budget $(BUDGET) --out $(OUT)

test:
	$(CARGO) test --locked

check:
	$(CARGO) fmt --check
	$(CARGO) clippy --locked --all-targets -- -D warnings
	$(CARGO) test --locked

bench:
	$(CARGO) bench --locked

golden:
	INSTA_UPDATE=always $(CARGO) test --locked --test golden
	git --no-pager diff --stat -- golden/

clean:
	$(CARGO) clean

# The paper's Fig. 2, both dimensions, publication-grade (standard error <= 0.01 F_c0).
fig2: build
	$(BIN) verify --scene compression-2d --scene compression-3d --budget full --out $(OUT)

# Convergence studies of the linear scenes (quick ensembles, about a minute in all):
# element count (h^4 mode rates with consistent noise, h^2 deficit of the paper's
# element-uniform noise) and time step (backward Euler O(dt), Crank-Nicolson exact).
CONVERGE_OUT ?= $(OUT)/convergence
converge: build
	$(BIN) converge --scene hinged-linear-2d --run crank-nicolson --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run element-uniform --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-3d --run exact-modal --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run backward-euler --over dt --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run crank-nicolson --over dt --budget $(BUDGET) --out $(CONVERGE_OUT)
