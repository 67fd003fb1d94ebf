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
