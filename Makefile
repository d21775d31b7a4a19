# rover-cosim: two commands set up everything —
#   make run    creates .venv if missing and runs the whole pipeline that exists so far
#   make test   creates .venv if missing and runs the test suite
#   make lint   ruff and mypy (configured in pyproject.toml); CI runs it before the tests
# Nothing else needs installing by hand: python3 (>= 3.11), gcc and make are enough.

PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: run test test-fast fuzz docs lint fig3 fmus fmus3 identify simulate montecarlo report cosim-study bench venv clean

# FMU build: BACKEND=auto uses OpenModelica's omc where it is on PATH, else the built-in
# rumoca -> CasADi -> C exporter; BACKEND=builtin or BACKEND=omc force one.
BACKEND ?= auto
# Soil, rover and wheel of fig3, identify and simulate: names of the shipped library
# (`rover-cosim soils`, `rover-cosim rovers`) or TOML files; WHEEL empty: the rover's own wheel.
# E.g. `make run SOIL=lunar_nominal ROVER=viper` or `make run SOIL=lunar_nominal WHEEL=mer`.
SOIL ?= paper
ROVER ?= paper
WHEEL ?=
# SET: single values changed for fig3, identify and simulate (each KIND.NAME=VALUE of `--set`, space-
# separated); RUTS=1: the straight run with multi-pass ruts (`simulate --ruts`). The wheel effects of
# issue 48, e.g. `make run SET="wheel.grouser_height=0.01 wheel.grouser_count=24 soil.n_slip=0.5" RUTS=1`.
SET ?=
RUTS ?=
SOIL_OPTIONS := --soil $(SOIL) --rover $(ROVER) $(if $(WHEEL),--wheel $(WHEEL)) $(foreach a,$(SET),--set $(a))
# Results: results/ for the paper's soil, rover and wheel; any other choice gets its own folder
# (results_<rover>_<soil>[_<wheel>][_<set>][_ruts]), so that its files never mix with the paper's.
name_of = $(basename $(notdir $(1)))
empty :=
space := $(empty) $(empty)
SET_NAME := $(subst =,-,$(subst $(space),_,$(strip $(SET))))
PAPER_CHOICE := $(and $(filter paper,$(SOIL)),$(filter paper,$(ROVER)),$(if $(WHEEL),$(filter paper,$(WHEEL)),yes),$(if $(SET)$(RUTS),,yes))
RESULTS ?= $(if $(PAPER_CHOICE),results,results_$(call name_of,$(ROVER))_$(call name_of,$(SOIL))$(if $(WHEEL),_$(call name_of,$(WHEEL)))$(if $(SET_NAME),_$(SET_NAME))$(if $(RUTS),_ruts))
# The FMUs are the classes of modelica/RoverTerramechanics/FMUs (its package.order): build-fmus without
# names builds them all; FMUS=Wheel,Rover (space- or comma-separated) builds some.
FMUS ?=
# binaries/ folders of the FMUs: host (this machine's, by cc), all (linux64 for glibc 2.17, win64,
# darwin64, aarch64-linux, aarch64-darwin; cross-compiled by zig from PyPI) or a comma-separated list.
PLATFORMS ?= host
# The FMUs' elementary functions (exp, log, pow, sin, cos, ...): libm (the C library's, the fastest on
# each host) or own (fmubuild/runtime/elementary.h: the same bits on every host; see docs/guide/fmus.md).
ELEMENTARY ?= libm
comma := ,

# The virtualenv is (re)installed when pyproject.toml changes; the stamp records success.
$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "rover-cosim needs Python >= 3.11, found " + sys.version.split()[0])'
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test,lint,platforms,docs]'
	@touch $@

venv: $(STAMP)

## run: the whole pipeline: FMUs -> Fig. 3 (reference wheel) -> identify -> simulate -> report
run: fmus fig3 identify simulate
	$(MAKE) report

## fig3: Fx against slip for loads 100..800 N -> results/fig3_fx_vs_slip.{csv,png}
fig3: $(STAMP)
	$(VENV)/bin/rover-cosim fig3 --out $(RESULTS) $(SOIL_OPTIONS)

## fmus: FMI 2.0 FMUs (ME + CS) of the Modelica models -> fmus/*.fmu (skipped when up to date);
## PLATFORMS=all adds the binaries of every host (see PLATFORMS above); ELEMENTARY=own: FMUs that give
## the same bits on every host (their own exp, log, sin, ...)
fmus: $(STAMP)
	$(VENV)/bin/rover-cosim build-fmus --out fmus --backend $(BACKEND) --platforms $(PLATFORMS) --elementary $(ELEMENTARY) $(subst $(comma), ,$(FMUS))

## fmus3: the same models as FMI 3.0 FMUs (ME + CS) -> fmus/fmi3/*.fmu (PLATFORMS as for fmus)
fmus3: $(STAMP)
	$(VENV)/bin/rover-cosim build-fmus --out fmus/fmi3 --backend builtin --fmi-version 3 --platforms $(PLATFORMS) --elementary $(ELEMENTARY) $(subst $(comma), ,$(FMUS))

## identify: paper Sec. 3 (sweep on SingleWheel.fmu, LUT, Fx fits, Table 1) -> results/identification/
identify: fmus
	$(VENV)/bin/rover-cosim identify --out $(RESULTS)/identification --fmu fmus/SingleWheel.fmu $(SOIL_OPTIONS)

## simulate: paper Sec. 4, closed loop on Rover.fmu and RoverBody + 6 Wheel, then the steerable rover's paths
## and side-slope traverses (issue 35), then the leg-wheel rover (issue 47; the paper's rover only) -> results/simulation/
simulate: identify
	$(VENV)/bin/rover-cosim simulate --out $(RESULTS)/simulation --fmu-dir fmus --model $(RESULTS)/identification/model.json $(SOIL_OPTIONS) $(if $(RUTS),--ruts)

## montecarlo: the closed loop on sampled lunar soils, controller unchanged -> results/montecarlo/
## STUDY: a study file or a shipped study; its nominal soil must be the one `make identify` used
## (SOIL/WHEEL; lunar_regolith: paper). MC_RUNS samples (nominal included; empty: the study's
## own number, 200 for lunar_regolith): a 20 s run costs ~1.6 s on one core, an adaptive one ~3.9 s;
## the 200 samples with MC_ADAPT (400 runs) took 9.7 min on 2 cores. MC_WORKERS local processes
## (default: all cores); MC_SCHEDULER=tcp://host:8786 runs on a Dask cluster instead.
STUDY ?= lunar_regolith
MC_RUNS ?=
MC_WORKERS ?=
MC_SCHEDULER ?=
# MC_ADAPT=1 (the default): every sample also runs with the adaptive controller (calibration, soil
# estimated from the rover's telemetry, model identified again), compared after the calibration;
# MC_ADAPT= leaves it out (about half the time).
MC_ADAPT ?= 1
# The Monte Carlo needs an identified model: made once (identify), not again while it is newer
# than the wheel FMU (a model of another soil is refused by the command, naming both).
$(RESULTS)/identification/model.json: fmus/SingleWheel.fmu
	$(MAKE) identify

fmus/SingleWheel.fmu:
	$(MAKE) fmus

montecarlo: $(STAMP) $(RESULTS)/identification/model.json
	$(VENV)/bin/rover-cosim montecarlo --study $(STUDY) $(if $(MC_RUNS),--runs $(MC_RUNS)) --out $(RESULTS)/montecarlo --fmu-dir fmus \
		--model $(RESULTS)/identification/model.json $(if $(MC_WORKERS),--workers $(MC_WORKERS)) \
		$(if $(MC_SCHEDULER),--scheduler $(MC_SCHEDULER)) $(if $(MC_ADAPT),--adapt)

## report: results/report.html (figures and tables beside the paper's, provenance)
report: $(STAMP)
	$(VENV)/bin/rover-cosim report --results $(RESULTS)

## cosim-study: coupling error of the co-simulated rover vs the monolithic one -> results/cosim_study/
cosim-study: fmus
	$(VENV)/bin/rover-cosim cosim-study --out $(RESULTS)/cosim_study --fmu-dir fmus

## test: the test suite (python -P keeps the checkout's folder off sys.path, as for an installed
## wheel; without it the layer folders still import only as rover_cosim.*: `import orchestrator`
## fails with a message, so `python -m pytest` works the same). On every core (pytest-xdist: TEST_WORKERS
## processes, each module on one of them so that its fixtures are built once; TEST_WORKERS=0 runs
## in this process); the 30 slowest tests listed at the end.
TEST_WORKERS ?= auto
TEST_PARALLEL := $(if $(filter 0,$(TEST_WORKERS)),,-n $(TEST_WORKERS) --dist loadscope)
# Compiled modules cached under .cache/pycache (not beside the sources), where the environment says
# PYTHONDONTWRITEBYTECODE: pytest otherwise rewrites the asserts of every test module in every worker
# on every run (the fast tier's collection 5.4 -> 2.8 s a worker), and each command a test starts
# compiles the project's modules again.
PYTEST := env -u PYTHONDONTWRITEBYTECODE PYTHONPYCACHEPREFIX=$(CURDIR)/.cache/pycache $(PY) -P -m pytest
test: $(STAMP)
	$(PYTEST) $(TEST_PARALLEL) --durations=30

## test-fast: the tests that build and run no FMU (physics, engine logic, CLI parsing, soils, report
## pages, fuzz): seconds, for the edit-test loop; make test runs them all
test-fast: $(STAMP)
	$(PYTEST) $(TEST_PARALLEL) -m "not fmu and not slow" -q

## fuzz: a seeded fuzz of hostile inputs through the command line (system files, studies, soils,
## options, model descriptions, report inputs): every case must end in a message and exit 0/1/2,
## change nothing outside its output and leave nothing half-written; minutes, not part of make test
SEED ?= 20261206
CASES ?= 600
fuzz: $(STAMP)
	$(PY) -P tests/fuzz_harness.py --seed $(SEED) --cases $(CASES)

## docs: the documentation site -> site/ (MkDocs; reference pages generated from the code)
docs: fmus
	$(VENV)/bin/mkdocs build --strict --site-dir site

## lint: ruff (rules in pyproject.toml) and mypy over the package, tests and benchmarks
lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/mypy

## bench: benchmarks (not tests) -> results/bench/*.json (installs the bench extra: ecospy)
## BASELINE=REV: the commit the commands are timed against side by side (default the previous one; empty: none)
BASELINE ?= HEAD~1
BENCH_STAMP := $(VENV)/.installed-bench
$(BENCH_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -e '.[bench]'
	@touch $@

bench: $(BENCH_STAMP)
	$(PY) -P benchmarks/bench_reference.py --out $(RESULTS)/bench/reference.json
	$(PY) -P benchmarks/bench_fmus.py --out $(RESULTS)/bench/fmus.json
	$(PY) -P benchmarks/bench_orchestrator.py --out $(RESULTS)/bench/orchestrator.json
	$(PY) -P benchmarks/bench_isolation.py --out $(RESULTS)/bench/isolation.json
	$(PY) -P benchmarks/bench_identification.py --out $(RESULTS)/bench/identification.json
	$(PY) -P benchmarks/bench_controller.py --out $(RESULTS)/bench/controller.json --model $(RESULTS)/identification/model.json
	$(PY) -P benchmarks/bench_soil_estimation.py --out $(RESULTS)/bench/soil_estimation.json --markdown $(RESULTS)/bench/soil_estimation.md
	$(PY) -P benchmarks/bench_quadrature.py --out $(RESULTS)/bench/quadrature.json --markdown $(RESULTS)/bench/quadrature.md
	$(PY) -P benchmarks/bench_elementary.py --out $(RESULTS)/bench/elementary.json --model $(RESULTS)/identification/model.json
	$(PY) -P benchmarks/bench_contact_limit.py --out $(RESULTS)/bench/contact_limit.json
	$(PY) -P benchmarks/bench_closed_loop.py --out $(RESULTS)/bench/closed_loop.json --model $(RESULTS)/identification/model.json
	$(PY) -P benchmarks/bench_path_following.py --out $(RESULTS)/bench/path_following.json --model $(RESULTS)/identification/model.json
	$(PY) -P benchmarks/bench_legwheel.py --out $(RESULTS)/bench/legwheel.json --model $(RESULTS)/identification/model.json
	$(PY) -P benchmarks/bench_pipeline.py --out $(RESULTS)/bench/pipeline.json $(if $(BASELINE),--baseline-rev $(BASELINE))

clean:
	rm -rf $(VENV) $(RESULTS) .pytest_cache .cache fmus/*.fmu fmus/.*.partial
