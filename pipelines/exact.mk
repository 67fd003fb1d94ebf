# The exact reference (paper 002 Sec. 2): mesh-prep -> exact -> tonemap, and
# compare of the hierarchical pipeline's preview against it.
# `make exact SCENE=simple-environment` renders $(OUT)/exact/image.exr and
# image.png and writes $(OUT)/exact/compare.ron (paper 002's "% of visible
# pixels over tau", per object) with its difference picture. Scenes exact
# cannot solve (occluders, curved surfaces; the default Cornell box) are
# refused with one line saying why. EXACT_BOUNCES=1 is the paper's
# one-bounce image; the default iterates until the further bounces between
# A and B are far under the tolerance, for comparing with a full solution.

EXACT_OUT := $(OUT)/exact
EXACT_BOUNCES ?= 20
EXACT_TOLERANCE ?= 1e-6

.PHONY: exact
exact: $(EXACT_OUT)/image.png $(EXACT_OUT)/compare.ron

$(EXACT_OUT) $(EXACT_OUT)/params:
	@mkdir -p $@

$(BIN)/exact: FORCE
	@cargo build --release --quiet -p exact --bins

$(EXACT_OUT)/params/exact.ron: $(BIN)/exact FORCE | $(EXACT_OUT)/params
	@$(BIN)/exact --print-params --bounces $(EXACT_BOUNCES) --tolerance $(EXACT_TOLERANCE) \
	  $(if $(WIDTH),--width $(WIDTH)) $(if $(HEIGHT),--height $(HEIGHT)) > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

$(EXACT_OUT)/image.exr: $(BIN)/exact $(EXACT_OUT)/params/exact.ron $(OUT)/mesh.exr $(OUT)/manifest.ron | $(EXACT_OUT)
	$(BIN)/exact --params $(EXACT_OUT)/params/exact.ron --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron \
	  -o $@ --report $(EXACT_OUT)/exact.report.ron

$(EXACT_OUT)/image.png: $(BIN)/tonemap $(OUT)/params/tonemap.ron $(EXACT_OUT)/image.exr
	$(BIN)/tonemap --params $(OUT)/params/tonemap.ron $(EXACT_OUT)/image.exr -o $@ --report $(EXACT_OUT)/tonemap.report.ron

# Paper 002's measure (Sec. 4.1): visible pixels whose relative difference
# exceeds tau = 10% and 15%, emitters and silhouettes left out (the exact
# image samples pixel centres, the preview averages SPP rays).
$(EXACT_OUT)/compare.ron: $(BIN)/compare $(OUT)/preview.exr $(EXACT_OUT)/image.exr
	$(BIN)/compare $(OUT)/preview.exr $(EXACT_OUT)/image.exr --tau 0.02,0.05,0.1,0.15 --exclude-emitters --exclude-edges 1 \
	  --manifest $(OUT)/manifest.ron --diff $(EXACT_OUT)/difference.png -o $@
