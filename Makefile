# langevin-fem — build, verify, test.
#
#   make verify            quick verification suite (CI), reports in reports/
#   make verify BUDGET=full   publication-grade error bars
#   make test              all tests (unit, integration, statistical validation, golden,
#                          every command shown in README.md and docs/), then `check`
#                          against the NumPy example simulator, the docs' NumPy blocks
#                          (docs-check), Fig. 2 in shards merged (fig2-shards), then the
#                          reports rendered in headless Chromium (browser-check)
#   make check             fmt --check, clippy -D warnings, tests
#   make docs              regenerate the guide's generated parts: the scene-key page
#                          (from src/scene/keys.rs), the commands page's --help blocks
#                          and the README's Fig. 2 (docs/src/images/fig2.svg)
#   make docs-check        the console blocks of README.md and docs/ tagged `numpy`, run
#                          with the NumPy venv of example-check (tests/docs.rs)
#   make bench             benchmarks (benches/), see docs/src/reference/performance.md
#   make golden            re-run golden snapshots, accept changes, show the diff
#   make fig2              the paper's Fig. 2 (compression scenes, full budget)
#   make fig2-shards       Fig. 2 as SHARDS concurrent shards and as an emulated Slurm array,
#                          each merged and compared byte for byte with the single run
#   make converge          convergence studies (orders in h and dt), reports/convergence/
#   make bench-peers       Fig. 2 against a plain NumPy implementation: CPU times and ratio
#   make calibrate         the verifier's false-alarm rate and p-value uniformity over
#                          SEEDS seeds (default 100), reports/calibration/
#   make power             fault injection: detection rate of each catalogued fault over seeds
#   make fit-coverage      coverage of `fit`'s 95 % intervals over SEEDS seeds (FIT_SCENE=…)

CARGO  ?= cargo
BUDGET ?= quick
OUT    ?= reports
BIN     = target/release/langevin-fem

.PHONY: all build verify test check bench golden clean fig2 fig2-shards converge bench-peers example-check browser-check calibrate power docs docs-check numpy-venv fit-coverage

all: build

build:
	$(CARGO) build --release --locked

# The reduced stability map (10 elements, four steps around the explicit limit, a few
# seconds) and a reduced compression convergence study (<F> at eps = 0 over 5, 10, 20
# elements, a few seconds) run first, so that the verification index links them; the map
# fails the target if an exact stationary-variance formula is rejected or a stability
# prediction fails.
verify: build
	$(BIN) stability --scene hinged-linear-2d --elements 10 --dt-lambda-max 0.1,1.9,2.1,1e3 --steps 20000 --out $(OUT)/convergence
	$(BIN) converge --scene compression-2d --over elements --values 5,10,20 --strain-ratios 0 --trajectories 16 --duration-tau1 200 --out $(OUT)/convergence
	$(BIN) verify --budget $(BUDGET) --out $(OUT)

# Calibration of the verifier (issue #16): every default scene verified at SEEDS seeds
# (seed k = 1 + k, each exactly `verify --scene S --seed <seed>`): the false-alarm rate
# per scene with its exact binomial interval against alpha, and the uniformity of the
# checks' p-values per check kind (KS, Holm), in $(OUT)/calibration/. Exit 1 if a scene's
# rate is above alpha or a kind's p-values are not uniform. About 60 s per seed at the
# quick budget on 2 cores (100 min for 100 seeds; the fig2-paper scenes take half).
SEEDS ?= 100
CALIBRATION_SCENES = actin-10um clamped-clamped-3d compression-2d compression-3d fig2-paper-2d fig2-paper-3d grafted-clamped-free hinged-linear-2d hinged-linear-3d membrane-area-paper membrane-area-soft membrane-area-stiff membrane-bilayer membrane-hinged membrane-periodic membrane-spectral microtubule-free-free pinned-free-2d spectral-reference tension-2d
calibrate: build
	$(BIN) calibrate $(foreach s,$(CALIBRATION_SCENES),--scene $(s)) --seeds $(SEEDS) --budget $(BUDGET) --out $(OUT)/calibration

# Coverage of `fit`'s 95 % intervals (issue #31): for seeds 1..SEEDS, `run` of
# FIT_SCENE's Crank-Nicolson run (default hinged-linear-2d) and `fit` of its output; how
# often each interval (EI or a membrane's kappa, xi, kT; for a membrane also kappa and
# sigma together) covers the truth, against the binomial range of 95 %, in
# $(OUT)/fit-coverage/coverage.csv. About 2 min for 100 seeds on 2 cores
# (FIT_SCENE=membrane-periodic: 3.4 min for 200).
FIT_SCENE ?= hinged-linear-2d
fit-coverage: build
	python3 examples/fit-coverage/coverage.py $(BIN) $(OUT)/fit-coverage --scene $(FIT_SCENE) --seeds $(SEEDS)

# Tests run in the release profile, so that `make test` and `make verify` share every
# compiled dependency (one build, not two: the time to first result on a fresh clone).
test:
	$(CARGO) test --release --locked
	$(MAKE) --no-print-directory example-check
	$(MAKE) --no-print-directory docs-check
	$(MAKE) --no-print-directory fig2-shards
	$(MAKE) --no-print-directory browser-check

# `check` against independent simulators (NumPy in a venv). examples/numpy-simulator:
# passes at a small time step, fails naming the biased modes at a large one; NumPy reads
# what `run` writes. examples/fd-simulator (a finite-difference filament): passes with its
# discretization declared (and `fit` recovers its EI), fails with the noise variance x1.05,
# and declared unknown fails against the continuum with every label saying so.
# examples/bead-spring-simulator (11 beads, springs and the full cosine angle potential):
# passes declared as "bead-spring", `fit` recovers its EI, fails with the noise x1.05.
# examples/membrane-simulator (a periodic membrane by Fourier-space Brownian dynamics):
# passes membrane-periodic's checks against the continuum, `fit` recovers kappa and sigma,
# fails with the noise x1.05. Part of `make test` (CI).
EXAMPLE_OUT ?= target/example-check
example-check: build numpy-venv
	examples/numpy-simulator/ci-check.sh $(PEERS_VENV)/bin/python $(BIN) $(EXAMPLE_OUT)
	examples/fd-simulator/ci-check.sh $(PEERS_VENV)/bin/python $(BIN) $(EXAMPLE_OUT)-fd
	examples/bead-spring-simulator/ci-check.sh $(PEERS_VENV)/bin/python $(BIN) $(EXAMPLE_OUT)-beads
	examples/membrane-simulator/ci-check.sh $(PEERS_VENV)/bin/python $(BIN) $(EXAMPLE_OUT)-membrane

# The venv with NumPy (pinned, PEERS_NUMPY) of example-check and docs-check.
numpy-venv:
	test -x $(PEERS_VENV)/bin/python || python3 -m venv $(PEERS_VENV)
	$(PEERS_VENV)/bin/python -c "import numpy" 2>/dev/null || $(PEERS_VENV)/bin/python -m pip install -q numpy==$(PEERS_NUMPY)

# The guide's commands (issue #26): `cargo test` runs every console block of README.md and
# docs/src/ (tests/docs.rs) except those tagged `numpy`, which run here, with the venv's
# Python as `python3`. Part of `make test`, after example-check.
docs-check: numpy-venv
	LANGEVIN_FEM_PYTHON=$(abspath $(PEERS_VENV))/bin/python $(CARGO) test --release --locked --test docs -- --ignored

# The guide's generated files: the page of scene keys, from the table in
# src/scene/keys.rs (a test in tests/docs.rs fails when the committed page differs from
# it), every `--help` block of the commands page (docs/dev/refresh_help.py; the docs test
# fails when one drifts), and the paper's Fig. 2 shown by the README (fig2-shards, part of `make test`,
# fails when the committed figure differs from the full-budget run's, byte for byte), and the
# README's filament from tension through buckling (tension-2d at the full budget, about 2 s; a
# test in tests/docs.rs fails when the committed figure differs from that run's, byte for byte),
# and the README's membrane under imposed projected area (both membrane-area scenes at the
# standard budget, about 80 s), and the README's cost of Fig. 2 per scheme (work-precision
# on fig2-paper-2d, about 2.5 min; CPU times are measured, so this one is not byte-stable).
SCENE_KEYS_PAGE = docs/src/reference/scene-keys.md
FIG2_IMAGE      = docs/src/images/fig2.svg
TENSION_IMAGE   = docs/src/images/tension-2d.svg
docs: build
	$(BIN) scene keys --format markdown > $(SCENE_KEYS_PAGE).tmp
	mv $(SCENE_KEYS_PAGE).tmp $(SCENE_KEYS_PAGE)
	python3 docs/dev/refresh_help.py $(BIN) docs/src/reference/commands.md
	$(BIN) verify -q $(FIG2_ARGS) --out target/docs-fig2
	mkdir -p $(dir $(FIG2_IMAGE))
	cp target/docs-fig2/fig2.svg $(FIG2_IMAGE)
	$(BIN) verify -q --scene tension-2d --budget full --out target/docs-tension
	cp target/docs-tension/tension-2d/force-strain.svg $(TENSION_IMAGE)
	$(BIN) verify -q --scene membrane-area-soft --scene membrane-area-stiff --budget standard --out target/docs-area
	cp target/docs-area/membrane-area-soft/force-strain.svg docs/src/images/membrane-area-soft.svg
	cp target/docs-area/membrane-area-stiff/force-strain.svg docs/src/images/membrane-area-stiff.svg
	$(BIN) work-precision -q --scene fig2-paper-2d --out target/docs-wp-fig2
	cp target/docs-wp-fig2/work-precision-fig2.svg docs/src/images/fig2-work-precision.svg

# The reports as a reader sees them (issue #14): a quick verification of every default
# scene (passing) and the example check's failing report (NumPy at a large step) rendered
# in headless Chromium (Debian's package, installed here if missing; playwright-core from
# the npm registry, pinned in tests/browser/package-lock.json): no console errors, failed
# requests or broken links; the verdict and the failures first; under 10 screen heights
# collapsed; every figure loads with a caption. Screenshots in $(BROWSER_SHOTS) (CI
# artefacts). Part of `make test`, after example-check (whose failing report it reads).
CHROMIUM      ?= /usr/bin/chromium
BROWSER_SHOTS ?= $(OUT)/browser
BROWSER_OUT   ?= target/browser-check
SUDO          := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
browser-check: build
	test -x $(CHROMIUM) || $(SUDO) apt-get install -y -q chromium || { $(SUDO) apt-get update -q && $(SUDO) apt-get install -y -q chromium; }
	cd tests/browser && npm ci --no-audit --no-fund --loglevel=error
	$(BIN) verify --out $(BROWSER_OUT)/passed > $(BROWSER_OUT).log 2>&1 || { cat $(BROWSER_OUT).log; exit 1; }
	CHROMIUM=$(CHROMIUM) node tests/browser/check-index.mjs --report $(BROWSER_OUT)/passed --expect passed --shots $(BROWSER_SHOTS) --name verify-passed
	CHROMIUM=$(CHROMIUM) node tests/browser/check-index.mjs --report $(EXAMPLE_OUT)/large-dt-report --expect failed --shots $(BROWSER_SHOTS) --name check-failed
	CHROMIUM=$(CHROMIUM) node tests/browser/check-index.mjs --report $(EXAMPLE_OUT)-fd/declared-report --expect passed --shots $(BROWSER_SHOTS) --name check-declared
	CHROMIUM=$(CHROMIUM) node tests/browser/check-index.mjs --report $(EXAMPLE_OUT)-fd/unknown-report --expect failed --shots $(BROWSER_SHOTS) --name check-continuum

check:
	$(CARGO) fmt --check
	$(CARGO) clippy --locked --all-targets -- -D warnings
	$(CARGO) test --release --locked

bench:
	$(CARGO) bench --locked

# Fault injection (src/fault.rs, issue #16): every catalogued simulator fault, per scene
# and size, verified at POWER_SEEDS fixed seeds at the quick budget; detection rates with
# Clopper-Pearson intervals in $(POWER_OUT)/power.{csv,json,md}. Builds with
# `--features faults`, which replaces target/release/langevin-fem by the faults build (a
# later `make verify` or `make build` relinks it without). About 30 min on 2 cores (the
# tension-2d targets, added with issue #28, about 4 of them).
POWER_OUT   ?= $(OUT)/power
POWER_SEEDS ?= 20
power:
	$(CARGO) run --release --locked --features faults -- power --seeds $(POWER_SEEDS) --budget quick --out $(POWER_OUT)

golden:
	INSTA_UPDATE=always $(CARGO) test --release --locked --test golden
	git --no-pager diff --stat -- golden/

clean:
	$(CARGO) clean

# The paper's Fig. 2, both dimensions, publication-grade (standard error <= 0.01 F_c0).
FIG2_ARGS = --scene compression-2d --scene compression-3d --budget full
fig2: build
	$(BIN) verify $(FIG2_ARGS) --out $(OUT)

# Fig. 2 split into SHARDS shards (issue #15): run concurrently on this machine
# (examples/slurm/parallel.sh: GNU parallel, or xargs -P without it) and as the Slurm
# job array of examples/slurm/ run in turn without Slurm (emulate.sh: the array tasks,
# shards 2..N with shard 1's plans, --plan-from, then the merge job), each merged; both
# force-strain.csv tables and fig2.svg must equal the single run's byte for byte. A few
# seconds; part of `make test` (CI).
SHARDS    ?= 4
SHARD_OUT ?= target/fig2-shards
fig2-shards: build
	rm -rf $(SHARD_OUT)
	$(BIN) verify -q $(FIG2_ARGS) --out $(SHARD_OUT)/single
	LANGEVIN_FEM=$(BIN) examples/slurm/parallel.sh $(SHARDS) $(SHARD_OUT)/parallel $(FIG2_ARGS)
	LANGEVIN_FEM=$(CURDIR)/$(BIN) SHARDS_DIR=$(SHARD_OUT)/array/shards REPORT_DIR=$(SHARD_OUT)/array/report \
		PLAN_FROM=$(CURDIR)/$(SHARD_OUT)/array/shards/1 VERIFY_ARGS="-q $(FIG2_ARGS)" \
		examples/slurm/emulate.sh $(SHARDS) >/dev/null
	for f in compression-2d/force-strain.csv compression-3d/force-strain.csv fig2.svg; do \
		cmp $(SHARD_OUT)/single/$$f $(SHARD_OUT)/parallel/report/$$f && \
		cmp $(SHARD_OUT)/single/$$f $(SHARD_OUT)/array/report/$$f || exit 1; \
	done
	@cmp $(SHARD_OUT)/single/fig2.svg $(FIG2_IMAGE) || { echo "$(FIG2_IMAGE) differs from the full-budget Fig. 2: run make docs and commit it"; exit 1; }
	@echo "fig2-shards: $(SHARDS) shards (concurrent, and as an emulated Slurm array) merged to the single run's force-strain.csv and fig2.svg, byte for byte"

# Convergence studies, written to reports/convergence/ with an index page (about 6 min
# after the build on 2 cores; see docs/src/reference/studies.md):
# - linear scenes over elements: h^4 mode variances with consistent noise (below the
#   sampling floor by design: the exact-error order is the check), the h^2 deficit of the
#   paper's element-uniform noise;
# - linear scenes over dt: backward Euler O(dt) (pre-asymptotic at these steps, stated
#   against the exact discrete error), Crank-Nicolson exact;
# - compression scenes over elements (<F> converges as h: the unresolved modes' stored
#   length) and over dt (Metropolis CN exact at any dt; Crank-Nicolson with the
#   stretching force explicit: O(dt) bias, unstable in tension beyond ~0.005 tau1);
# - the extreme scenes (very stiff, floppy with the small-slope warning, linear and under
#   compression, 1000 elements, EA L/kT = 1e9 with Metropolis, the membrane stiff, near
#   buckling, dominated by tension and on a 24 x 24 mesh; the explicit scheme at 1e9
#   must stop naming the step);
# - the work-precision study; the stability map (last: it rebuilds the index page).
# The ensembles of the studies that resolve observed orders are set here, not by BUDGET.
CONVERGE_OUT ?= $(OUT)/convergence
ELEMENT_UNIFORM_ENSEMBLE ?= --trajectories 64 --duration-tau1 200
BACKWARD_EULER_ENSEMBLE ?= --trajectories 64 --duration-tau1 100
# 40 tau1 (the quick budget) gives about 80 effectively independent samples of mode 1 per
# trajectory: too few for its autocorrelation-aware error (low estimates come with low
# errors), so this exactness study samples 160 tau1.
CRANK_NICOLSON_DT_ENSEMBLE ?= --trajectories 16 --duration-tau1 160
COMPRESSION_ENSEMBLE ?= --trajectories 16 --duration-tau1 1000
COMPRESSION_DT_ENSEMBLE ?= --trajectories 16 --duration-tau1 400
EXPLICIT_STRETCH_ENSEMBLE ?= --trajectories 32 --duration-tau1 1000
converge: build
	$(BIN) converge --scene hinged-linear-2d --run crank-nicolson --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run element-uniform --over elements $(ELEMENT_UNIFORM_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-3d --run exact-modal --over elements --budget $(BUDGET) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run backward-euler --over dt --values 0.016,0.008,0.004,0.002 $(BACKWARD_EULER_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) converge --scene hinged-linear-2d --run crank-nicolson --over dt $(CRANK_NICOLSON_DT_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) converge --scene compression-2d --over elements $(COMPRESSION_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) converge --scene compression-3d --over elements $(COMPRESSION_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) converge --scene compression-2d --over dt $(COMPRESSION_DT_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) converge --scene compression-3d --over dt $(COMPRESSION_DT_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) converge --scene compression-2d --over dt --integrator crank-nicolson --values 0.004,0.003,0.002,0.001 --strain-ratios 0 $(EXPLICIT_STRETCH_ENSEMBLE) --out $(CONVERGE_OUT)
	$(BIN) verify --scene verification/extreme/hinged-stiff-2d.toml --scene verification/extreme/hinged-floppy-2d.toml --scene verification/extreme/hinged-1000-2d.toml --scene verification/extreme/compression-stiff-ea-2d.toml --scene verification/extreme/compression-floppy-2d.toml --scene verification/extreme/membrane-stiff.toml --scene verification/extreme/membrane-near-buckling.toml --scene verification/extreme/membrane-tension-dominated.toml --scene verification/extreme/membrane-fine.toml --budget $(BUDGET) --out $(CONVERGE_OUT)/extreme
	@if $(BIN) verify --scene verification/extreme/compression-stiff-ea-explicit-2d.toml --budget quick --out $(CONVERGE_OUT)/extreme-ea-explicit 2> $(CONVERGE_OUT)/extreme/compression-stiff-ea-explicit-2d.log; then \
		echo "compression-stiff-ea-explicit-2d: expected to stop naming the step where it diverged, but it ran"; exit 1; \
	elif grep -q "unstable at step" $(CONVERGE_OUT)/extreme/compression-stiff-ea-explicit-2d.log; then \
		echo "compression-stiff-ea-explicit-2d: stopped as expected:"; cat $(CONVERGE_OUT)/extreme/compression-stiff-ea-explicit-2d.log; \
	else cat $(CONVERGE_OUT)/extreme/compression-stiff-ea-explicit-2d.log; exit 1; fi
	$(BIN) work-precision --scene hinged-linear-2d --out $(CONVERGE_OUT)
	$(BIN) stability --scene hinged-linear-2d --out $(CONVERGE_OUT)

# Fig. 2 (both dimensions, full budget: s.e. <= 0.01 F_c0 at every strain) by langevin-fem
# and by the plain NumPy peer benches/peers/fig2_numpy.py (256 vectorized trajectories,
# exact bending modes, the stretching force explicit, stopped at the same target standard
# error), each timed by benches/peers/cpu_time.py (user + sys CPU of the child, all
# threads); prints both CPU and wall times and the ratio numpy / langevin-fem. NumPy runs
# in benches/peers/.venv with its default threads; OPENBLAS_CORETYPE and OPENBLAS_L2_SIZE
# (set on some machines for old OpenBLAS builds) are unset for that command alone, and the
# script prints the BLAS kernel it runs. The NumPy results are compared with the exact
# theory of the same 10-element filament (deviation in standard errors per strain).
# Not like for like: langevin-fem's time includes the whole verify scene (the step
# search, the pilot and main stage of its budget by target precision, the dt-halving run
# at dt/2, the force-distribution checks, the exact theories, the report); the NumPy peer
# stops each strain at the target and does nothing else. Results: the guide's
# docs/src/reference/performance.md.
PEERS_OUT    ?= $(OUT)/bench-peers
PEERS_VENV   ?= benches/peers/.venv
PEERS_NUMPY  ?= 2.4.6
PEERS_RATIOS  = 0,0.5,1,1.5,2,2.5,3,4,5,6,8,10
bench-peers: build
	test -x $(PEERS_VENV)/bin/python || python3 -m venv $(PEERS_VENV)
	$(PEERS_VENV)/bin/python -m pip install -q numpy==$(PEERS_NUMPY) threadpoolctl==3.8.0
	mkdir -p $(PEERS_OUT)
	rm -f $(PEERS_OUT)/cpu.jsonl
	$(BIN) theory compression --dims 2 --strain-ratio $(PEERS_RATIOS) --elements 10 --persistence-ratio 100 --stretch-ratio 1e6 > $(PEERS_OUT)/theory-2d.json
	$(BIN) theory compression --dims 3 --strain-ratio $(PEERS_RATIOS) --elements 10 --persistence-ratio 100 --stretch-ratio 1e6 > $(PEERS_OUT)/theory-3d.json
	@echo "load before: $$(uptime)"
	python3 benches/peers/cpu_time.py run --label langevin-fem --record $(PEERS_OUT)/cpu.jsonl -- \
		$(BIN) verify --scene compression-2d --scene compression-3d --budget full --out $(PEERS_OUT)
	python3 benches/peers/cpu_time.py run --label numpy --record $(PEERS_OUT)/cpu.jsonl -- \
		env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE $(PEERS_VENV)/bin/python benches/peers/fig2_numpy.py \
		--theory $(PEERS_OUT)/theory-2d.json --theory $(PEERS_OUT)/theory-3d.json
	@echo "load after: $$(uptime)"
	@python3 benches/peers/cpu_time.py compare $(PEERS_OUT)/cpu.jsonl
