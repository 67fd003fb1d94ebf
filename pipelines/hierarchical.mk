# The hierarchical pipeline: mesh-prep -> [cluster] -> hierarchical-solve ->
# grid-gather (preview) -> tonemap. Every intermediate lands in $(OUT);
# every stage also writes its report (work done, wall time) beside its
# output. CLUSTERS=0 leaves the cluster stage out.
CLUSTERS_EXR := $(if $(filter 1,$(CLUSTERS)),$(OUT)/clusters.exr)

$(eval $(call params_file,mesh-prep,))
$(eval $(call params_file,cluster,))
# SHADOW_LEVELS: how many 1:4 levels below MIN_AREA a shadow edge may split
# (hierarchical-solve's --shadow-levels).
SHADOW_LEVELS ?= 2
$(eval $(call params_file,hierarchical-solve,--eps $(EPS) --min-area $(MIN_AREA) --shadow-levels $(SHADOW_LEVELS) --visibility-rays $(VISIBILITY_RAYS) --tolerance $(TOLERANCE) --seed $(SEED)))
$(eval $(call params_file,grid-gather,--spp $(SPP) $(if $(WIDTH),--width $(WIDTH)) $(if $(HEIGHT),--height $(HEIGHT))))
$(eval $(call params_file,tonemap,--operator $(OPERATOR)))

# mesh-prep writes $(OUT)/mesh.d: the mesh and manifest depend on every
# file it read (the scene file, each OBJ, MTL, texture and photometric
# file). Before the first run there is none, and nothing to be stale.
# $(OUT)/params/scene holds the scene argument, rewritten only when it
# changes, so that naming another scene for the same OUT reruns it too.
$(OUT)/params/scene: FORCE | $(OUT)/params
	@echo "$(SCENE_ARGS)" > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

# surface.exr: texture coordinates, shading normals and decoded textures
# (empty for a scene without surface detail), for the stages that simulate
# them.
$(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr &: $(BIN)/mesh-prep $(OUT)/params/mesh-prep.ron $(OUT)/params/scene | $(OUT)
	$(BIN)/mesh-prep $(SCENE_ARGS) --params $(OUT)/params/mesh-prep.ron \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr --report $(OUT)/mesh-prep.report.ron --depfile $(OUT)/mesh.d
-include $(OUT)/mesh.d

$(OUT)/clusters.exr: $(BIN)/cluster $(OUT)/params/cluster.ron $(OUT)/mesh.exr $(OUT)/manifest.ron
	$(BIN)/cluster --params $(OUT)/params/cluster.ron --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron -o $@ --report $(OUT)/cluster.report.ron

# The clustering choice, rewritten only when it changes, so that switching
# CLUSTERS reruns the solve.
$(OUT)/params/clusters: FORCE | $(OUT)/params
	@echo "$(CLUSTERS)" > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

$(OUT)/solution.exr: $(BIN)/hierarchical-solve $(OUT)/params/hierarchical-solve.ron $(OUT)/params/clusters $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr $(CLUSTERS_EXR)
	$(BIN)/hierarchical-solve --params $(OUT)/params/hierarchical-solve.ron \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr $(if $(CLUSTERS_EXR),--clusters $(CLUSTERS_EXR)) -o $@ --report $(OUT)/solve.report.ron

# grid-gather reads surface.exr only for a scene with textures, alpha masks
# or normal maps (the display modulates by the texture per hit).
$(OUT)/preview.exr: $(BIN)/grid-gather $(OUT)/params/grid-gather.ron $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr $(OUT)/solution.exr
	$(BIN)/grid-gather --params $(OUT)/params/grid-gather.ron --mode preview \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr --solution $(OUT)/solution.exr -o $@ --report $(OUT)/gather.report.ron

$(OUT)/image.png: $(BIN)/tonemap $(OUT)/params/tonemap.ron $(OUT)/preview.exr
	$(BIN)/tonemap --params $(OUT)/params/tonemap.ron $(OUT)/preview.exr -o $@ --report $(OUT)/tonemap.report.ron

# --- the full final gather of paper 000 --------------------------------
# `make full` renders $(OUT)/final.png: hierarchical-solve -> grid-gather
# preview -> tonemap -> [mask] -> grid-gather full -> tonemap. MASK=1 puts
# the mask stage in (the full gather's threshold then follows the preview's
# visual masking); without it the gather uses its `contrast` parameter.
# The default target stays the preview (`make`), which takes well under a
# second on the Cornell box; the full gather takes a few seconds there.
MASK ?=
GATHER_FLAGS ?=

$(eval $(call params_file,mask,))

$(BIN)/mask: FORCE
	@cargo build --release --quiet --bin mask

$(OUT)/threshold.exr: $(BIN)/mask $(OUT)/params/mask.ron $(OUT)/image.png
	$(BIN)/mask --params $(OUT)/params/mask.ron $(OUT)/image.png -o $@ --report $(OUT)/mask.report.ron

$(OUT)/params/grid-gather-full.ron: $(BIN)/grid-gather FORCE | $(OUT)/params
	@$(BIN)/grid-gather --print-params --mode full --spp $(SPP) $(if $(LATTICE_SPACING),--lattice-spacing $(LATTICE_SPACING)) $(if $(WIDTH),--width $(WIDTH)) $(if $(HEIGHT),--height $(HEIGHT)) $(GATHER_FLAGS) > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

$(OUT)/final.exr $(OUT)/final.diagnostics.exr &: $(BIN)/grid-gather $(OUT)/params/grid-gather-full.ron $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr $(OUT)/solution.exr $(if $(MASK),$(OUT)/threshold.exr) $(CLUSTERS_EXR)
	$(BIN)/grid-gather --params $(OUT)/params/grid-gather-full.ron \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr --solution $(OUT)/solution.exr $(if $(MASK),--threshold $(OUT)/threshold.exr) $(if $(CLUSTERS_EXR),--clusters $(CLUSTERS_EXR)) \
	  -o $(OUT)/final.exr --diagnostics $(OUT)/final.diagnostics.exr --report $(OUT)/final.report.ron

$(OUT)/final.png: $(BIN)/tonemap $(OUT)/params/tonemap.ron $(OUT)/final.exr
	$(BIN)/tonemap --params $(OUT)/params/tonemap.ron $(OUT)/final.exr -o $@ --report $(OUT)/final-tonemap.report.ron

.PHONY: full bench-gather bench-mask
full: $(OUT)/final.png

# Tables 1-2 of paper 000 in shape: brute force and the full gather (with
# and without masking) against a high-sample brute-force reference, on the
# unclustered Cornell box (at BENCH_EPS) at BENCH_SIZE^2 pixels (the surface-based
# gather's case: walls refined finer than the grid) and on the clustered plant room
# (mesh-prep's plants-10k, cluster, hierarchical-solve --clusters at eps
# 1e-2) at BENCH_PLANT_SIZE^2. Figures (bench-gather, bench/src/gather.rs):
# each run's report (visibility_rays, classification_visibility_rays,
# form_factor_evaluations, wall_time_s) and compare's relative RMSE, in
# out/bench-gather/summary.txt and out/bench-gather-plants/summary.txt;
# `brute_rays@err` is the brute-force ray count at the run's error, on the
# brute runs' least-squares log(rays)-log(error) line.
BENCH_SIZE ?= 128
# The Cornell box's refinement threshold for this benchmark (not make's
# EPS): at 2e-4 it solves in about 1.5 s to 94k links; at the default
# 1.5e-5 (1.2M links) brute force at 4 samples per link is already within
# 8e-5 relative RMSE of the reference, the reference alone takes a quarter
# of an hour on 2 cores, and the table compares nothing (README).
BENCH_EPS ?= 2e-4
# Contrast thresholds of the unmasked full runs (`full<c>`): the price of
# accuracy.
BENCH_CONTRASTS ?= 0.02 0.005
BENCH_PLANT_SIZE ?= 64
BENCH_OUT := out/bench-gather
BENCH_PLANTS := out/bench-gather-plants
BG_ARGS = --mesh $(BENCH_OUT)/mesh.exr --manifest $(BENCH_OUT)/manifest.ron --solution $(BENCH_OUT)/solution.exr --width $(BENCH_SIZE) --height $(BENCH_SIZE)
BP_ARGS = --mesh $(BENCH_PLANTS)/mesh.exr --manifest $(BENCH_PLANTS)/manifest.ron --solution $(BENCH_PLANTS)/solution.exr --clusters $(BENCH_PLANTS)/clusters.exr --width $(BENCH_PLANT_SIZE) --height $(BENCH_PLANT_SIZE)

# bench_runs(dir, args, reference samples, brute sample counts): the
# reference, the brute runs, full and masked, and the summary table.
define bench_runs
	$(BIN)/grid-gather $(2) --brute --brute-samples $(3) -o $(1)/reference.exr --report $(1)/reference.report.ron
	for n in $(4); do $(BIN)/grid-gather $(2) --brute --brute-samples $$n -o $(1)/brute$$n.exr --report $(1)/brute$$n.report.ron; done
	for c in $(BENCH_CONTRASTS); do $(BIN)/grid-gather $(2) --mode full --contrast $$c --diagnostics $(1)/full$$c.diagnostics.exr -o $(1)/full$$c.exr --report $(1)/full$$c.report.ron; done
	$(BIN)/grid-gather $(2) --mode full --threshold $(1)/threshold.exr --diagnostics $(1)/masked.diagnostics.exr -o $(1)/masked.exr --report $(1)/masked.report.ron
	$(BIN)/bench-gather --dir $(1) -o $(1)/summary.txt $(addprefix brute,$(4)) $(addprefix full,$(BENCH_CONTRASTS)) masked
endef

bench-gather: $(BINS) $(BENCH_BINS) $(BIN)/mask
	@mkdir -p $(BENCH_OUT) $(BENCH_PLANTS)
	$(MAKE) --no-print-directory OUT=$(BENCH_OUT) CLUSTERS=0 EPS=$(BENCH_EPS) WIDTH=$(BENCH_SIZE) HEIGHT=$(BENCH_SIZE) $(BENCH_OUT)/threshold.exr
	$(call bench_runs,$(BENCH_OUT),$(BG_ARGS),256,4 8 16 64)
	$(BIN)/mesh-prep --builtin plants-10k --mesh $(BENCH_PLANTS)/mesh.exr --manifest $(BENCH_PLANTS)/manifest.ron
	$(BIN)/cluster --mesh $(BENCH_PLANTS)/mesh.exr --manifest $(BENCH_PLANTS)/manifest.ron -o $(BENCH_PLANTS)/clusters.exr
	$(BIN)/hierarchical-solve --mesh $(BENCH_PLANTS)/mesh.exr --manifest $(BENCH_PLANTS)/manifest.ron --clusters $(BENCH_PLANTS)/clusters.exr --eps 1e-2 -o $(BENCH_PLANTS)/solution.exr --report $(BENCH_PLANTS)/solve.report.ron
	$(BIN)/grid-gather $(BP_ARGS) --mode preview -o $(BENCH_PLANTS)/preview.exr
	$(BIN)/tonemap --operator $(OPERATOR) $(BENCH_PLANTS)/preview.exr -o $(BENCH_PLANTS)/preview.png
	$(BIN)/mask $(BENCH_PLANTS)/preview.png -o $(BENCH_PLANTS)/threshold.exr
	$(call bench_runs,$(BENCH_PLANTS),$(BP_ARGS),128,4 8 16)

# Paper 000 Table 1 in shape (never in `make test`): the full gather with
# and without the visual mask on a room whose floor is a fine, high-contrast
# checkerboard (bench-mask scene, bench/src/mask/), unclustered, at
# BENCH_MASK_SIZE^2 pixels, against a brute-force reference of
# BENCH_MASK_REFERENCE samples per link. The mask reads the tone-mapped
# preview, which shows the texture (grid-gather --surface); the row
# masked-untextured takes its mask from a preview without --surface (the
# mask blind to the texture). Table (rays,
# form factors, time, relative RMSE over the image and on the floor, share
# of pixels whose error exceeds the mask's threshold) in
# out/bench-mask/summary.txt.
BENCH_MASK_SIZE ?= 128
BENCH_MASK_REFERENCE ?= 64
BENCH_MASK := out/bench-mask
BM_UNTEXTURED = --mesh $(BENCH_MASK)/mesh.exr --manifest $(BENCH_MASK)/manifest.ron --solution $(BENCH_MASK)/solution.exr --width $(BENCH_MASK_SIZE) --height $(BENCH_MASK_SIZE)
BM_ARGS = $(BM_UNTEXTURED) --surface $(BENCH_MASK)/surface.exr
bench-mask: $(BINS) $(BENCH_BINS) $(BIN)/mask
	@mkdir -p $(BENCH_MASK)/untextured
	$(BIN)/bench-mask scene --dir $(BENCH_MASK)/scene --width $(BENCH_MASK_SIZE) --height $(BENCH_MASK_SIZE)
	$(MAKE) --no-print-directory SCENE=$(BENCH_MASK)/scene/scene.ron OUT=$(BENCH_MASK) CLUSTERS=0 WIDTH=$(BENCH_MASK_SIZE) HEIGHT=$(BENCH_MASK_SIZE) $(BENCH_MASK)/threshold.exr
	$(BIN)/grid-gather $(BM_ARGS) --brute --brute-samples $(BENCH_MASK_REFERENCE) -o $(BENCH_MASK)/reference.exr --report $(BENCH_MASK)/reference.report.ron
	$(BIN)/grid-gather $(BM_ARGS) --mode full -o $(BENCH_MASK)/unmasked.exr --report $(BENCH_MASK)/unmasked.report.ron
	$(BIN)/grid-gather $(BM_ARGS) --mode full --threshold $(BENCH_MASK)/threshold.exr -o $(BENCH_MASK)/masked.exr --report $(BENCH_MASK)/masked.report.ron
	$(BIN)/grid-gather $(BM_UNTEXTURED) --mode preview -o $(BENCH_MASK)/untextured/preview.exr --report $(BENCH_MASK)/untextured/preview.report.ron
	$(BIN)/tonemap --params $(BENCH_MASK)/params/tonemap.ron $(BENCH_MASK)/untextured/preview.exr -o $(BENCH_MASK)/untextured/preview.png
	$(BIN)/mask --params $(BENCH_MASK)/params/mask.ron $(BENCH_MASK)/untextured/preview.png -o $(BENCH_MASK)/untextured/threshold.exr
	$(BIN)/grid-gather $(BM_ARGS) --mode full --threshold $(BENCH_MASK)/untextured/threshold.exr -o $(BENCH_MASK)/masked-untextured.exr --report $(BENCH_MASK)/masked-untextured.report.ron
	$(BIN)/bench-mask summary --dir $(BENCH_MASK) -o $(BENCH_MASK)/summary.txt unmasked masked-untextured masked
