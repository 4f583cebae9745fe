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

# The reduced stability map (10 elements, four steps around the explicit limit, a few
# seconds) runs first, so that the verification index links it; it fails the target if
# an exact stationary-variance formula is rejected or a stability prediction fails.
verify: build
	$(BIN) stability --scene hinged-linear-2d --elements 10 --dt-lambda-max 0.1,1.9,2.1,1e3 --steps 20000 --out $(OUT)/convergence
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

# Convergence studies (quick ensembles, a few minutes in all), written to
# reports/convergence/ with an index page: element count (h^4 mode rates with consistent
# noise, h^2 deficit of the paper's element-uniform noise) and time step (backward Euler
# O(dt), Crank-Nicolson exact); the extreme scenes (very stiff, floppy with the
# small-slope warning, 1000 elements; huge EA must fail naming the acceptance rate); the
# work-precision study; the stability map (last: it rebuilds the index page).
CONVERGE_OUT ?= $(OUT)/convergence
converge: build
	$(BIN) converge --scene hinged-linear-2d --run crank-nicolson --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run element-uniform --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-3d --run exact-modal --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run backward-euler --over dt --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run crank-nicolson --over dt --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) verify --scene verification/extreme/hinged-stiff-2d.toml --scene verification/extreme/hinged-floppy-2d.toml --scene verification/extreme/hinged-1000-2d.toml --budget $(BUDGET) --out $(CONVERGE_OUT)/extreme
	@if $(BIN) verify --scene verification/extreme/compression-stiff-ea-2d.toml --budget quick --out $(CONVERGE_OUT)/extreme-ea 2> $(CONVERGE_OUT)/extreme/compression-stiff-ea-2d.log; then \
		echo "compression-stiff-ea-2d: expected a failure naming the acceptance rate, but it ran"; exit 1; \
	elif grep -q "acceptance rate" $(CONVERGE_OUT)/extreme/compression-stiff-ea-2d.log; then \
		echo "compression-stiff-ea-2d: refused as expected:"; cat $(CONVERGE_OUT)/extreme/compression-stiff-ea-2d.log; \
	else cat $(CONVERGE_OUT)/extreme/compression-stiff-ea-2d.log; exit 1; fi
	$(BIN) work-precision --scene hinged-linear-2d --out $(CONVERGE_OUT)
	$(BIN) stability --scene hinged-linear-2d --out $(CONVERGE_OUT)
