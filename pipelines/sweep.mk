# The sweep: error against time over a grid of knob values. `make sweep`
# prepares $(SCENE) once, then for every point of the grid and every
# repetition runs cluster + hierarchical-solve (or gpu-shoot), grid-gather
# in each gather mode and compare against the reference, and writes
# $(OUT)/sweep/sweep.ron, sweep.csv, sweep.svg and sweep.png (log-log
# error against total time, one curve per solver and gather mode, the
# Pareto front ringed); each point's runs are kept under runs/, the
# reference under reference/. The reference is the scene's closed form
# where it has one (the integrating sphere, sphere-<n>), else
# REFERENCE=path.exr, else a run stricter than every point (said so in the
# table and the plot). It always reruns: times are measurements.
#
# The pipeline's own knobs (EPS, SPP, ...) are not read here: the sweep
# sets them per point. Examples:
#   make sweep                                   # Cornell box, EPS 1e-3 .. 1e-5, preview and full
#   make sweep SWEEP_KNOB=EPS SWEEP_VALUES=1e-2,1e-3,1e-4 SWEEP_GATHER=preview
#   make sweep SWEEP_KNOBS="EPS=1e-3,3e-4 SPP=4,16"   # a 2 x 2 grid
#   make sweep SCENE=sphere-1k SWEEP_REPS=1      # closed-form reference
#   make sweep SWEEP_SOLVER=gpu                  # GPU_CONVERGENCE 0.8 .. 0.999
#   make sweep SWEEP_SOLVER=hierarchical,gpu,photon   # three curves
#   make sweep SCENE=simple-environment SWEEP_SOLVER=hierarchical,structured

# hierarchical, gpu, photon (photon-trace, PHOTON_TARGET_ERROR 0.2 .. 0.025),
# structured (structured-sample, STRUCTURED_LEVELS 2 .. 16; its own display
# instead of a gather), comma-separated: each sweeps its own grid.
SWEEP_SOLVER ?= hierarchical
# Gather modes (preview, full; space- or comma-separated); empty: every
# mode the solver allows (full needs the hierarchical solver's links).
SWEEP_GATHER ?=
# One knob and its values, e.g. SWEEP_KNOB=EPS SWEEP_VALUES=1e-2,1e-3.
# Knobs: EPS, MIN_AREA, VISIBILITY_RAYS, TOLERANCE (hierarchical);
# GPU_TEXELS, GPU_CONVERGENCE, GPU_RESOLUTION, GPU_SHOOT_LEVEL (gpu); SPP;
# LATTICE_SPACING (the full gather's).
SWEEP_KNOB ?=
SWEEP_VALUES ?=
# Several knobs, space-separated NAME=v1,v2 (the grid is their product).
# With no knob, each solver sweeps its default (EPS=1e-3,3e-4,1e-4,3e-5,1e-5;
# GPU_CONVERGENCE=0.8,0.9,0.99,0.999).
SWEEP_KNOBS ?=
# Runs per point; every figure is the median over them.
SWEEP_REPS ?= 3
# A reference image (EXR, e.g. another renderer's) for scenes without a
# closed form; compared leaving out emitters and 2 pixels around edges.
REFERENCE ?=
SWEEP_OUT := $(OUT)/sweep

sweep_comma := ,
sweep_space := $(subst ,, )

.PHONY: sweep
sweep: $(BINS) $(BENCH_BINS) $(call sweep_bins,$(SWEEP_SOLVER))
	$(if $(SWEEP_KNOB),$(if $(SWEEP_VALUES),,$(error SWEEP_KNOB=$(SWEEP_KNOB) needs SWEEP_VALUES=v1,v2,...)))
	$(BIN)/sweep --scene $(SCENE) --solver $(SWEEP_SOLVER) $(if $(strip $(SWEEP_GATHER)),--gather $(subst $(sweep_space),$(sweep_comma),$(strip $(SWEEP_GATHER)))) \
	  $(if $(SWEEP_KNOB),--knob $(SWEEP_KNOB)=$(SWEEP_VALUES)) $(foreach k,$(SWEEP_KNOBS),--knob $(k)) \
	  --reps $(SWEEP_REPS) $(if $(REFERENCE),--reference $(REFERENCE)) $(if $(filter 0,$(CLUSTERS)),--no-clusters) \
	  $(if $(WIDTH),--width $(WIDTH)) $(if $(HEIGHT),--height $(HEIGHT)) -o $(SWEEP_OUT)
