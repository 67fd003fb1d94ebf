# The hierarchical pipeline: mesh-prep -> hierarchical-solve -> grid-gather
# (preview) -> tonemap. Every intermediate lands in $(OUT); every stage also
# writes its report (work done, wall time) beside its output.

$(eval $(call params_file,mesh-prep,))
$(eval $(call params_file,hierarchical-solve,--eps $(EPS) --min-area $(MIN_AREA) --visibility-rays $(VISIBILITY_RAYS) --tolerance $(TOLERANCE) --seed $(SEED)))
$(eval $(call params_file,grid-gather,--spp $(SPP) $(if $(WIDTH),--width $(WIDTH)) $(if $(HEIGHT),--height $(HEIGHT))))
$(eval $(call params_file,tonemap,--operator $(OPERATOR)))

$(OUT)/mesh.exr $(OUT)/manifest.ron &: $(BIN)/mesh-prep $(OUT)/params/mesh-prep.ron $(SCENE_FILES) | $(OUT)
	$(BIN)/mesh-prep $(SCENE_ARGS) --params $(OUT)/params/mesh-prep.ron \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --report $(OUT)/mesh-prep.report.ron

$(OUT)/solution.exr: $(BIN)/hierarchical-solve $(OUT)/params/hierarchical-solve.ron $(OUT)/mesh.exr $(OUT)/manifest.ron
	$(BIN)/hierarchical-solve --params $(OUT)/params/hierarchical-solve.ron \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron -o $@ --report $(OUT)/solve.report.ron

$(OUT)/preview.exr: $(BIN)/grid-gather $(OUT)/params/grid-gather.ron $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/solution.exr
	$(BIN)/grid-gather --params $(OUT)/params/grid-gather.ron --mode preview \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --solution $(OUT)/solution.exr -o $@ --report $(OUT)/gather.report.ron

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
	@$(BIN)/grid-gather --print-params --mode full --spp $(SPP) $(if $(WIDTH),--width $(WIDTH)) $(if $(HEIGHT),--height $(HEIGHT)) $(GATHER_FLAGS) > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

$(OUT)/final.exr $(OUT)/final.diagnostics.exr &: $(BIN)/grid-gather $(OUT)/params/grid-gather-full.ron $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/solution.exr $(if $(MASK),$(OUT)/threshold.exr)
	$(BIN)/grid-gather --params $(OUT)/params/grid-gather-full.ron \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --solution $(OUT)/solution.exr $(if $(MASK),--threshold $(OUT)/threshold.exr) \
	  -o $(OUT)/final.exr --diagnostics $(OUT)/final.diagnostics.exr --report $(OUT)/final.report.ron

$(OUT)/final.png: $(BIN)/tonemap $(OUT)/params/tonemap.ron $(OUT)/final.exr
	$(BIN)/tonemap --params $(OUT)/params/tonemap.ron $(OUT)/final.exr -o $@ --report $(OUT)/final-tonemap.report.ron

.PHONY: full bench-gather
full: $(OUT)/final.png

# Tables 1-2 of paper 000 in shape: brute force and the full gather (with
# and without masking) against a high-sample brute-force reference, on the
# Cornell box at BENCH_SIZE^2 pixels. Figures: each run's report
# (visibility_rays, form_factor_evaluations, wall_time_s) and compare's
# relative RMSE, gathered in out/bench-gather/summary.txt.
BENCH_SIZE ?= 128
BENCH_OUT := out/bench-gather
BG_ARGS = --mesh $(BENCH_OUT)/mesh.exr --manifest $(BENCH_OUT)/manifest.ron --solution $(BENCH_OUT)/solution.exr --width $(BENCH_SIZE) --height $(BENCH_SIZE)
bench-gather: $(BINS) $(BIN)/mask
	@mkdir -p $(BENCH_OUT)
	$(MAKE) --no-print-directory OUT=$(BENCH_OUT) WIDTH=$(BENCH_SIZE) HEIGHT=$(BENCH_SIZE) $(BENCH_OUT)/threshold.exr
	$(BIN)/grid-gather $(BG_ARGS) --brute --brute-samples 256 -o $(BENCH_OUT)/reference.exr --report $(BENCH_OUT)/reference.report.ron
	$(BIN)/grid-gather $(BG_ARGS) --brute --brute-samples 16 -o $(BENCH_OUT)/brute16.exr --report $(BENCH_OUT)/brute16.report.ron
	$(BIN)/grid-gather $(BG_ARGS) --brute --brute-samples 64 -o $(BENCH_OUT)/brute64.exr --report $(BENCH_OUT)/brute64.report.ron
	$(BIN)/grid-gather $(BG_ARGS) --mode full -o $(BENCH_OUT)/full.exr --report $(BENCH_OUT)/full.report.ron
	$(BIN)/grid-gather $(BG_ARGS) --mode full --threshold $(BENCH_OUT)/threshold.exr -o $(BENCH_OUT)/masked.exr --report $(BENCH_OUT)/masked.report.ron
	@for r in brute16 brute64 full masked; do \
	  printf '%-8s ' $$r; \
	  grep -oE '"(visibility_rays|form_factor_evaluations|classification_visibility_rays)": [0-9.e+]+' $(BENCH_OUT)/$$r.report.ron | tr '\n' ' '; \
	  grep -oE 'wall_time_s: [0-9.]+' $(BENCH_OUT)/$$r.report.ron | tr '\n' ' '; \
	  $(BIN)/compare $(BENCH_OUT)/$$r.exr $(BENCH_OUT)/reference.exr -o $(BENCH_OUT)/$$r.compare.ron 2>&1 | grep -oE 'relative_rmse [0-9.e-]+'; \
	done | tee $(BENCH_OUT)/summary.txt
