# Radiosity pipeline. `make` renders the default scene (the built-in Cornell
# box) to out/cornell/image.png; `make test` runs every test; `make bench`
# runs the benchmarks. Every knob below can be set on the command line
# (`make EPS=3e-4`); only the stages it affects run again.

.DELETE_ON_ERROR:
.SUFFIXES:
SHELL := bash

# --- scene -------------------------------------------------------------
# SCENE=cornell (the default), simple-environment (paper 002's) and the sized
# procedural scenes (plants-100k, sphere-5k, box-100k, cornell-box-2k, ...)
# are built into mesh-prep;
# anything that names an existing file is a scene.ron path. The files a
# scene reads (OBJ, MTL, textures, photometric files, wherever they lie)
# are listed by mesh-prep itself in $(OUT)/mesh.d, which the pipelines
# include: a change to any of them reruns mesh-prep and what follows.
SCENE ?= cornell
ifeq ($(SCENE),cornell)
  SCENE_ARGS := --builtin cornell-box
  SCENE_NAME := cornell
else ifneq ($(wildcard $(SCENE)),)
  SCENE_ARGS := $(SCENE)
  SCENE_NAME := $(notdir $(patsubst %/,%,$(dir $(abspath $(SCENE)))))
else
  SCENE_ARGS := --builtin $(SCENE)
  SCENE_NAME := $(SCENE)
endif
OUT ?= out/$(SCENE_NAME)

# --- knobs (defaults are the stages' own) -------------------------------
# CLUSTERS=1 solves with the cluster hierarchy (the cluster stage), 0 links
# every pair of input triangles. The large procedural scenes default to a
# coarser refinement threshold: 1.5e-5 of the lamp's exitance is chosen for
# the Cornell box's full gather (hierarchical-solve's RELATIVE_AT), far
# stricter than a 100k-triangle plant room needs.
CLUSTERS ?= 1
ifneq ($(filter plants-% box-% sphere-%,$(SCENE)),)
  EPS ?= 1e-3
endif
EPS ?= 1.5e-5
MIN_AREA ?= 1e-4
VISIBILITY_RAYS ?= 16
TOLERANCE ?= 1e-5
SEED ?= 1
WIDTH ?=
HEIGHT ?=
SPP ?= 4
# Full gather: pixels between its lattice's points; empty: grid-gather's default.
LATTICE_SPACING ?=
OPERATOR ?= reinhard

BIN := target/release
STAGES := mesh-prep cluster hierarchical-solve grid-gather tonemap compare
BINS := $(addprefix $(BIN)/,$(STAGES))

.PHONY: all test fuzz bench clean FORCE
all: $(OUT)/image.png

# Cargo decides what to rebuild; a binary it leaves alone keeps its time
# stamp, so the stages downstream of it do not run again.
$(BINS) &: FORCE
	@cargo build --release --quiet $(addprefix -p ,$(STAGES)) --bins

# The benchmark drivers (bench-solve, bench-scale, sweep, bench-gather's
# summary, bench-structured, bench-mask, bench-surfaces).
BENCH_BINS := $(addprefix $(BIN)/,bench-solve bench-scale sweep bench-gather bench-structured bench-mask bench-surfaces)
$(BENCH_BINS) &: FORCE
	@cargo build --release --quiet -p bench --bins

# sweep_bins(text): the stages a sweep whose solvers are named in `text`
# runs besides the hierarchical pipeline's, and exact, which renders the
# reference where it can (the pipelines' fragments build each).
sweep_bins = $(BIN)/exact $(if $(findstring gpu,$(1)),$(BIN)/gpu-shoot) \
  $(if $(findstring photon,$(1)),$(BIN)/photon-trace) $(if $(findstring structured,$(1)),$(BIN)/structured-sample)

# params_file(stage, flags): the stage's effective parameters as RON,
# rewritten only when they change, so a knob reruns only what it affects.
define params_file
$(OUT)/params/$(1).ron: $(BIN)/$(1) FORCE | $(OUT)/params
	@$(BIN)/$(1) --print-params $(2) > $$@.new && { cmp -s $$@.new $$@ && rm $$@.new || mv $$@.new $$@; }
endef

$(OUT) $(OUT)/params:
	@mkdir -p $@

# Every pipeline fragment; each is self-contained.
include $(sort $(wildcard pipelines/*.mk))

# The end-to-end tests and the sweep's run every stage's binary (photon-trace,
# structured-sample, exact, ... too), which cargo test alone builds only for
# crates with tests of their own: build them all first.
.PHONY: all-bins
all-bins:
	cargo build --release --workspace --bins

test: all-bins
	cargo test --release --workspace

# The mutation fuzz targets (tests named fuzz_*: OBJ, MTL, scene.ron, ...)
# for many more cases than `make test` runs (300 each); FUZZ_SEED picks
# another master seed, FUZZ_REPLAY=<case> reruns one reported case.
FUZZ_CASES ?= 20000
fuzz: all-bins
	FUZZ_CASES=$(FUZZ_CASES) cargo test --release --workspace -- fuzz_

# Medians of 5 solves of the Cornell box at about 10k leaf elements, and
# obvhs's raw traversal rate measured in the same run (see README).
bench: $(BINS) $(BENCH_BINS) | out
	$(BIN)/bench-solve -o out/bench-solve.ron

# Clustering at scale: plant rooms of 10k, 100k and 1M triangles (see README).
.PHONY: bench-scale
bench-scale: $(BINS) $(BENCH_BINS) | out
	$(BIN)/bench-scale --sizes $(or $(SIZES),10k,100k,1m) -o out/bench-scale.ron

out:
	@mkdir -p $@

clean:
	rm -rf out
