# Radiosity pipeline. `make` renders the default scene (the built-in Cornell
# box) to out/cornell/image.png; `make test` runs every test; `make bench`
# runs the benchmarks. Every knob below can be set on the command line
# (`make EPS=3e-4`); only the stages it affects run again.

.DELETE_ON_ERROR:
.SUFFIXES:
SHELL := bash

# --- scene -------------------------------------------------------------
# SCENE=cornell is built into mesh-prep; anything else is a scene.ron path.
SCENE ?= cornell
ifeq ($(SCENE),cornell)
  SCENE_ARGS := --builtin cornell-box
  SCENE_FILES :=
  SCENE_NAME := cornell
else
  SCENE_ARGS := $(SCENE)
  SCENE_FILES := $(SCENE) $(wildcard $(dir $(SCENE))*.obj $(dir $(SCENE))*.mtl)
  SCENE_NAME := $(notdir $(patsubst %/,%,$(dir $(abspath $(SCENE)))))
endif
OUT ?= out/$(SCENE_NAME)

# --- knobs (defaults are the stages' own) -------------------------------
EPS ?= 2e-4
MIN_AREA ?= 1e-4
VISIBILITY_RAYS ?= 16
TOLERANCE ?= 1e-5
SEED ?= 1
WIDTH ?=
HEIGHT ?=
SPP ?= 4
OPERATOR ?= reinhard

BIN := target/release
STAGES := mesh-prep hierarchical-solve grid-gather tonemap compare
BINS := $(addprefix $(BIN)/,$(STAGES))

.PHONY: all test bench clean FORCE
all: $(OUT)/image.png

# Cargo decides what to rebuild; a binary it leaves alone keeps its time
# stamp, so the stages downstream of it do not run again.
$(BINS) &: FORCE
	@cargo build --release --quiet --bins

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

test: $(BINS)
	cargo test --release --workspace

# Medians of 5 solves of the Cornell box at about 10k leaf elements, and
# obvhs's raw traversal rate measured in the same run (see README).
bench: $(BINS) | out
	$(BIN)/bench-solve -o out/bench-solve.ron

out:
	@mkdir -p $@

clean:
	rm -rf out
