# `make mitsuba`: the scene as a Mitsuba 3 scene, $(OUT)/mitsuba/scene.xml
# with its PLY meshes in $(OUT)/mitsuba/scene/ (export-mitsuba; render with
# `mitsuba -Dspp=256 scene.xml`).
#
# `make bench-peer`: this pipeline against Mitsuba 3 on the same scene
# (bench/peer/bench_peer.py says how). A benchmark only: never part of
# `make test` or CI. It installs Mitsuba from PyPI into $(PEER_VENV) when
# missing and, run as root on Debian without libLLVM 19, installs libllvm19
# (Mitsuba's llvm_ad_rgb aborts with Debian 12's libLLVM 15; without it the
# script falls back to scalar_rgb, some 10x slower). Writes into $(PEER_OUT):
# reference.exr and its two halves, sweep/ (the pipeline's sweep against
# that reference), time_to_error.txt (printed too), points.csv and
# time_to_error.svg. About 20 minutes with the defaults on 2 cores; the
# reference (PEER_REF_BUDGET_S) is kept and reused while the scene and the
# variant stay the same.

MITSUBA_XML := $(OUT)/mitsuba/scene.xml
PEER_OUT ?= $(OUT)/peer
PEER_VENV ?= out/peer-venv
PEER_MITSUBA ?= mitsuba
# auto: llvm_ad_rgb where it works, else scalar_rgb.
PEER_VARIANT ?= auto
# Mitsuba's points (samples per pixel) and repetitions per point (a point
# whose first render takes over PEER_REP_CAP_S seconds runs once).
PEER_SPP ?= 1,4,16,64,256,1024,4096
PEER_REPS ?= 3
PEER_REP_CAP_S ?= 20
PEER_TARGETS ?= 0.05,0.02,0.01
# Render time the reference may take; it stops earlier once its noise is a
# fifth of the smallest target.
PEER_REF_BUDGET_S ?= 480
# Extra flags of the pipeline's sweep (e.g. --knob EPS=0.01,0.001 --reps 1).
PEER_SWEEP_FLAGS ?=
# PEER_SWEEP=0: no sweep, only Mitsuba's points and the images below (for
# a scene whose every solve takes minutes, such as the mirror boxes).
PEER_SWEEP ?= 1
# Other pipeline images of the scene whose error against the same
# reference is reported, NAME=IMAGE each, built by make first: e.g.
# PEER_ALSO='gpu-shoot=$(OUT)/gpu/preview.exr full=$(OUT)/final.exr' for
# both solvers on a scene with mirrors (make bench-mirror-peer).
PEER_ALSO ?=

.PHONY: mitsuba bench-peer
mitsuba: $(MITSUBA_XML)

$(BIN)/export-mitsuba: FORCE
	@cargo build --release --quiet -p export-mitsuba

$(MITSUBA_XML): $(BIN)/export-mitsuba $(OUT)/mesh.exr $(OUT)/manifest.ron
	@mkdir -p $(@D)
	$(BIN)/export-mitsuba --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron -o $@ --report $(@D)/export.report.ron

$(PEER_VENV)/.installed:
	python3 -m venv $(PEER_VENV)
	$(PEER_VENV)/bin/pip install --quiet $(PEER_MITSUBA) numpy
	@touch $@

bench-peer: $(BINS) $(BENCH_BINS) $(call sweep_bins,$(PEER_SWEEP_FLAGS)) $(OUT)/preview.exr $(foreach a,$(PEER_ALSO),$(lastword $(subst =, ,$(a)))) $(MITSUBA_XML) | $(PEER_VENV)/.installed
	@mkdir -p $(PEER_OUT)
	@if [ "$(PEER_VARIANT)" != scalar_rgb ] && ! ls /usr/lib/x86_64-linux-gnu/libLLVM.so.19* /usr/lib/x86_64-linux-gnu/libLLVM-19.so* >/dev/null 2>&1; then \
	  if [ "$$(id -u)" = 0 ] && apt-cache show libllvm19 >/dev/null 2>&1; then \
	    echo "bench-peer: installing libllvm19 for Mitsuba's llvm_ad_rgb"; apt-get install -y -q libllvm19 >/dev/null; \
	  else echo "bench-peer: no libLLVM 19 here (apt-get install libllvm19 as root): Mitsuba may fall back to scalar_rgb"; fi; \
	fi
	$(PEER_VENV)/bin/python bench/peer/bench_peer.py --xml $(MITSUBA_XML) --pipeline-image $(OUT)/preview.exr \
	  --manifest $(OUT)/manifest.ron --compare $(BIN)/compare --out $(PEER_OUT) --variant $(PEER_VARIANT) \
	  --spp $(PEER_SPP) --reps $(PEER_REPS) --rep-cap-s $(PEER_REP_CAP_S) --targets $(PEER_TARGETS) --ref-budget-s $(PEER_REF_BUDGET_S) \
	  $(foreach a,$(PEER_ALSO),--also $(a)) \
	  --sweep '$(if $(filter 1,$(PEER_SWEEP)),$(BIN)/sweep --scene $(SCENE) --reference {reference} -o {out}/sweep $(PEER_SWEEP_FLAGS))' --sweep-csv $(PEER_OUT)/sweep/sweep.csv
