# The photon pipeline (paper 001): mesh-prep -> photon-trace (photons into
# the mesh, kd-tree filter, exact direct light on a perceptually split
# mesh, photons for the indirect light) -> grid-gather (preview) -> tonemap.
# `make photon` renders $(OUT)/photon/image.png and the paper's Figure 1
# sequence from the run's snapshots: figure1a-stochastic.png (end of stage
# 1), figure1b-direct.png (after the direct pass), figure1c-final.png, with
# their times in timeline.txt. `make bench-photon` runs the Figure 1
# timeline on a plant room of about 17,000 polygons. The mesh and manifest
# are the hierarchical pipeline's.

PHOTON_OUT := $(OUT)/photon
# The vertices' target error. The preview's error against a path-traced
# reference stops falling near 2% (the Cornell box: 2.53% at 2%, 2.57% at
# 1%, which takes four times the photons): what is left is the photon
# mesh's resolution, not noise.
PHOTON_TARGET ?= 0.02
PHOTON_MAX ?= 67108864
PHOTON_FLAGS ?=

.PHONY: photon bench-photon
photon: $(PHOTON_OUT)/image.png $(PHOTON_OUT)/figure1a-stochastic.png $(PHOTON_OUT)/figure1b-direct.png $(PHOTON_OUT)/figure1c-final.png $(PHOTON_OUT)/timeline.txt

$(PHOTON_OUT) $(PHOTON_OUT)/params $(PHOTON_OUT)/snapshots:
	@mkdir -p $@

$(BIN)/photon-trace: FORCE
	@cargo build --release --quiet -p photon-trace --bins

$(PHOTON_OUT)/params/photon-trace.ron: $(BIN)/photon-trace FORCE | $(PHOTON_OUT)/params
	@$(BIN)/photon-trace --print-params --seed $(SEED) --target-error $(PHOTON_TARGET) --max-photons $(PHOTON_MAX) $(PHOTON_FLAGS) > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

$(PHOTON_OUT)/solution.exr $(PHOTON_OUT)/snapshots/stochastic.exr $(PHOTON_OUT)/snapshots/direct.exr &: $(BIN)/photon-trace $(PHOTON_OUT)/params/photon-trace.ron $(OUT)/mesh.exr $(OUT)/manifest.ron | $(PHOTON_OUT)/snapshots
	$(BIN)/photon-trace --params $(PHOTON_OUT)/params/photon-trace.ron --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron \
	  -o $(PHOTON_OUT)/solution.exr --snapshot-dir $(PHOTON_OUT)/snapshots --report $(PHOTON_OUT)/photon-trace.report.ron

# photon_image(name, solution): the preview of one solution (gpu.mk's
# preview, with the surface detail), tone mapped. photon-trace transports
# with each material's diffuse reflectance and treats alpha-masked surfaces
# as opaque (it says so in its report's skipped effects), so a textured
# scene's preview shows the texture times an irradiance solved without it.
define photon_image
$(call preview,$(2),$(PHOTON_OUT)/$(1).exr,$(PHOTON_OUT)/$(1).gather.report.ron)

$(PHOTON_OUT)/$(1).png: $(BIN)/tonemap $(OUT)/params/tonemap.ron $(PHOTON_OUT)/$(1).exr
	$(BIN)/tonemap --params $(OUT)/params/tonemap.ron $(PHOTON_OUT)/$(1).exr -o $$@ --report $(PHOTON_OUT)/$(1).tonemap.report.ron
endef

$(eval $(call photon_image,preview,$(PHOTON_OUT)/solution.exr))
$(eval $(call photon_image,figure1a-stochastic,$(PHOTON_OUT)/snapshots/stochastic.exr))
$(eval $(call photon_image,figure1b-direct,$(PHOTON_OUT)/snapshots/direct.exr))

$(PHOTON_OUT)/image.png: $(PHOTON_OUT)/preview.png
	cp $< $@

$(PHOTON_OUT)/figure1c-final.png: $(PHOTON_OUT)/preview.png
	cp $< $@

# photon_timeline(report): the Figure 1 times and the error curve of a run.
define photon_timeline
	@awk -F'[:,]' '/"(first_image_s|stage1_s|direct_s|final_s|stage1_photons|stage3_photons|vertices|leaves|splits|converged|max_relative_error)"/ { gsub(/[ "]/, "", $$1); printf "%-20s %s\n", $$1, $$2 }' $(1)
	@echo "error against time (stage photons seconds max_error mean_error):"
	@awk -F'[:,]' '/"curve\./ { split($$1, k, "."); if (k[2] != last && last != "") row(); last = k[2]; f = k[3]; gsub(/"/, "", f); v[f] = $$2 } \
	  function row() { printf "  %d %12d %9.3f %10.3e %10.3e\n", v["stage"], v["photons"], v["seconds"], v["max_error"], v["mean_error"] } \
	  END { if (last != "") row() }' $(1)
endef

$(PHOTON_OUT)/timeline.txt: $(PHOTON_OUT)/solution.exr
	$(call photon_timeline,$(PHOTON_OUT)/photon-trace.report.ron) > $@
	@cat $@

# Paper 001's Figure 1 timeline on a plant room of about 17,000 polygons
# (mesh-prep's plants-17k): time to the first displayable image (the first
# round of photons), to the end of the direct pass, and to the final
# criterion (BENCH_PHOTON_TARGET, at most BENCH_PHOTON_MAX photons), with the
# error against time; in out/bench-photon/timeline.txt, and the three
# images beside it.
BENCH_PHOTON := out/bench-photon
BENCH_PHOTON_SCENE ?= plants-17k
BENCH_PHOTON_TARGET ?= 0.02
BENCH_PHOTON_MAX ?= 4194304
bench-photon: $(BINS) $(BIN)/photon-trace | out
	@mkdir -p $(BENCH_PHOTON)/snapshots
	$(BIN)/mesh-prep --builtin $(BENCH_PHOTON_SCENE) --mesh $(BENCH_PHOTON)/mesh.exr --manifest $(BENCH_PHOTON)/manifest.ron
	$(BIN)/photon-trace --mesh $(BENCH_PHOTON)/mesh.exr --manifest $(BENCH_PHOTON)/manifest.ron --target-error $(BENCH_PHOTON_TARGET) --max-photons $(BENCH_PHOTON_MAX) \
	  -o $(BENCH_PHOTON)/solution.exr --snapshot-dir $(BENCH_PHOTON)/snapshots --report $(BENCH_PHOTON)/photon-trace.report.ron
	for s in snapshots/stochastic snapshots/direct solution; do \
	  $(BIN)/grid-gather --mode preview --mesh $(BENCH_PHOTON)/mesh.exr --manifest $(BENCH_PHOTON)/manifest.ron --solution $(BENCH_PHOTON)/$$s.exr -o $(BENCH_PHOTON)/$$(basename $$s)-preview.exr && \
	  $(BIN)/tonemap --operator $(OPERATOR) $(BENCH_PHOTON)/$$(basename $$s)-preview.exr -o $(BENCH_PHOTON)/$$(basename $$s).png; done
	$(call photon_timeline,$(BENCH_PHOTON)/photon-trace.report.ron) | tee $(BENCH_PHOTON)/timeline.txt
