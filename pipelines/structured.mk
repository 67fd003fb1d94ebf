# The structured-sampling pipeline (paper 002 Sec. 3): mesh-prep ->
# structured-sample (samples.exr, and its display: grid resampling with the
# conical filter, image.exr) -> tonemap, into $(OUT)/structured/.
# `make structured SCENE=simple-environment` renders
# $(OUT)/structured/image.png; where the exact stage's pipeline is present
# (pipelines/exact.mk, target $(OUT)/exact/image.exr) and the scene is one
# it solves (STRUCTURED_COMPARE=1, the default for simple-environment; the
# exact stage refuses scenes with occluders such as the Cornell box) it
# also writes $(OUT)/structured/compare.ron, paper 002's "% of visible
# pixels over tau" per object against the exact image, with its
# difference picture.
# STRUCTURED_BOUNCES=1 (with EXACT_BOUNCES=1) is the paper's one-bounce
# configuration; the default, 0, shoots until the unshot power is under
# the threshold, as the exact stage's default iterates every bounce.

STRUCTURED_OUT := $(OUT)/structured
STRUCTURED_BOUNCES ?= 0
STRUCTURED_FLAGS ?=
STRUCTURED_COMPARE ?= $(if $(filter simple-environment,$(SCENE)),1)

.PHONY: structured
structured: $(STRUCTURED_OUT)/image.png $(if $(and $(wildcard pipelines/exact.mk),$(STRUCTURED_COMPARE)),$(STRUCTURED_OUT)/compare.ron)

$(STRUCTURED_OUT) $(STRUCTURED_OUT)/params:
	@mkdir -p $@

$(BIN)/structured-sample: FORCE
	@cargo build --release --quiet -p structured-sample --bins

$(STRUCTURED_OUT)/params/structured-sample.ron: $(BIN)/structured-sample FORCE | $(STRUCTURED_OUT)/params
	@$(BIN)/structured-sample --print-params --bounces $(STRUCTURED_BOUNCES) $(STRUCTURED_FLAGS) \
	  $(if $(WIDTH),--width $(WIDTH)) $(if $(HEIGHT),--height $(HEIGHT)) > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

$(STRUCTURED_OUT)/samples.exr $(STRUCTURED_OUT)/image.exr &: $(BIN)/structured-sample $(STRUCTURED_OUT)/params/structured-sample.ron $(OUT)/mesh.exr $(OUT)/manifest.ron | $(STRUCTURED_OUT)
	$(BIN)/structured-sample --params $(STRUCTURED_OUT)/params/structured-sample.ron --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron \
	  -o $(STRUCTURED_OUT)/samples.exr --image $(STRUCTURED_OUT)/image.exr --report $(STRUCTURED_OUT)/structured-sample.report.ron

$(STRUCTURED_OUT)/image.png: $(BIN)/tonemap $(OUT)/params/tonemap.ron $(STRUCTURED_OUT)/image.exr
	$(BIN)/tonemap --params $(OUT)/params/tonemap.ron $(STRUCTURED_OUT)/image.exr -o $@ --report $(STRUCTURED_OUT)/tonemap.report.ron

# The measure of paper 002 Sec. 4.1 (as pipelines/exact.mk takes it for
# the preview): emitters and silhouettes left out.
$(STRUCTURED_OUT)/compare.ron: $(BIN)/compare $(STRUCTURED_OUT)/image.exr $(OUT)/exact/image.exr
	$(BIN)/compare $(STRUCTURED_OUT)/image.exr $(OUT)/exact/image.exr --tau 0.02,0.05,0.1,0.15 --exclude-emitters --exclude-edges 1 \
	  --manifest $(OUT)/manifest.ron --diff $(STRUCTURED_OUT)/difference.png -o $@

# `make bench-structured`: paper 002's Tables 2 and 3 in shape
# (bench-structured, bench/src/structured/): structured-sample at its
# defaults against hierarchical-solve (preview gather) over an EPS grid,
# with the hierarchical runs at the same speed, at the same quality and,
# per surface, with the fewest element vertices for structured sampling's
# figure there; percent of pixels over tau per surface, samples and
# element vertices per surface, the light-to-A / A-to-B time split where
# the reports have one. First the simple environment against the exact
# image (quality compared at tau 5% and paper 002's 10%), then the Cornell
# box (Table 3's 15%) against BENCH_STRUCTURED_REFERENCE: by default
# `make bench-peer`'s Mitsuba image where it has been rendered, else a
# converged hierarchical-solve full gather (EPS a quarter of the smallest
# swept, SPP 16), which the table says is not an independent truth.
# Writes bench.ron, bench.csv and bench.txt (printed too) under
# $(BENCH_STRUCTURED_OUT)/<scene>/. About 2 minutes on 2 cores with the
# Mitsuba reference, 8 without (the converged reference). A benchmark
# only: never in `make test`.
BENCH_STRUCTURED_OUT ?= out/bench-structured
# BENCH_STRUCTURED_EPS: the simple environment's EPS grid (default:
# bench-structured's own, which brackets structured sampling's figures).
BENCH_STRUCTURED_EPS ?=
BENCH_STRUCTURED_CORNELL_EPS ?= 0.0004,0.000125,0.00004,0.0000125
BENCH_STRUCTURED_REFERENCE ?= $(wildcard out/cornell/peer/reference.exr)
BENCH_STRUCTURED_CORNELL_SURFACES := --surface floor=floor --surface walls=back_wall,green_wall,red_wall \
  --surface ceiling=ceiling --surface blocks=short_block,tall_block

.PHONY: bench-structured
bench-structured: $(BINS) $(BENCH_BINS) $(BIN)/structured-sample $(BIN)/exact
	$(BIN)/bench-structured --scene simple-environment $(if $(BENCH_STRUCTURED_EPS),--eps $(BENCH_STRUCTURED_EPS)) --quality-tau 0.05,0.1 \
	  -o $(BENCH_STRUCTURED_OUT)/simple-environment
	$(BIN)/bench-structured --scene cornell --eps $(BENCH_STRUCTURED_CORNELL_EPS) --quality-tau 0.15 $(BENCH_STRUCTURED_CORNELL_SURFACES) \
	  $(if $(BENCH_STRUCTURED_REFERENCE),--reference $(BENCH_STRUCTURED_REFERENCE)) -o $(BENCH_STRUCTURED_OUT)/cornell
