# The GPU pipeline: mesh-prep -> gpu-shoot (progressive radiosity, wgpu; on
# lavapipe where no GPU exists) -> grid-gather (preview) -> tonemap.
# `make gpu` renders $(OUT)/gpu/image.png; `make bench-gpu` runs the GPU
# benchmark. The mesh and manifest are the hierarchical pipeline's.

GPU_OUT := $(OUT)/gpu
GPU_TEXELS ?= 32768
GPU_VISIBILITY ?= hemicube
GPU_CONVERGENCE ?= 0.999
GPU_SHOOT_LEVEL ?= 3
GPU_RESOLUTION ?= 128
# Ambient overshooting is off by default: by the unshot magnitude
# sum |dB| A it takes more shots (README, gpu-shoot).
GPU_OVERSHOOT ?= --no-overshoot

.PHONY: gpu bench-gpu bench-gpu-detail
gpu: $(GPU_OUT)/image.png

$(GPU_OUT) $(GPU_OUT)/params:
	@mkdir -p $@

$(BIN)/gpu-shoot: FORCE
	@cargo build --release --quiet -p gpu-shoot --bins

$(BIN)/bench-gpu: FORCE
	@cargo build --release --quiet -p bench --bin bench-gpu

$(GPU_OUT)/params/gpu-shoot.ron: $(BIN)/gpu-shoot FORCE | $(GPU_OUT)/params
	@$(BIN)/gpu-shoot --print-params --texels $(GPU_TEXELS) --visibility $(GPU_VISIBILITY) --convergence-target $(GPU_CONVERGENCE) \
	  --shoot-level $(GPU_SHOOT_LEVEL) --resolution $(GPU_RESOLUTION) $(GPU_OVERSHOOT) > $@.new && { cmp -s $@.new $@ && rm $@.new || mv $@.new $@; }

# surface.exr: textures, alpha masks and normal maps, which gpu-shoot
# simulates per texel (read only for a scene that has them).
$(GPU_OUT)/solution.exr $(GPU_OUT)/lightmap.exr &: $(BIN)/gpu-shoot $(GPU_OUT)/params/gpu-shoot.ron $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr | $(GPU_OUT)
	$(BIN)/gpu-shoot --params $(GPU_OUT)/params/gpu-shoot.ron --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr \
	  -o $(GPU_OUT)/solution.exr --lightmap $(GPU_OUT)/lightmap.exr --convergence-log $(GPU_OUT)/convergence.ron \
	  --plot $(GPU_OUT)/convergence.svg --report $(GPU_OUT)/gpu-shoot.report.ron

# preview(solution, image, report[, lightmap]): grid-gather's preview of a
# solution of the prepared scene, with its surface detail as
# hierarchical.mk passes it (read only for a scene with textures, alpha
# masks or normal maps: the display modulates the element's irradiance by
# the texture per hit, taking as the element's reflectance the texture
# average where the solver read surface.exr, as gpu-shoot does, else the
# material's), showing gpu-shoot's lightmap where one is given (README,
# gpu-shoot). photon.mk uses it too (the pipelines are included in name
# order).
define preview
$(2): $(BIN)/grid-gather $(OUT)/params/grid-gather.ron $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr $(1) $(4)
	$(BIN)/grid-gather --params $(OUT)/params/grid-gather.ron --mode preview \
	  --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr --solution $(1) $(if $(4),--lightmap $(4)) -o $$@ --report $(3)
endef

$(eval $(call preview,$(GPU_OUT)/solution.exr,$(GPU_OUT)/preview.exr,$(GPU_OUT)/gather.report.ron,$(GPU_OUT)/lightmap.exr))

$(GPU_OUT)/image.png: $(BIN)/tonemap $(OUT)/params/tonemap.ron $(GPU_OUT)/preview.exr
	$(BIN)/tonemap --params $(OUT)/params/tonemap.ron $(GPU_OUT)/preview.exr -o $@ --report $(GPU_OUT)/tonemap.report.ron

# Cornell box at about 127k texels to 90% convergence: hemicube vs
# stereographic, with and without overshooting (see README, Performance).
bench-gpu: $(BIN)/bench-gpu | out
	$(BIN)/bench-gpu -o out/bench-gpu.ron

# The shape of paper 004 Table 2.1: a closed box with and without a normal
# map, the Cornell box with and without adaptive subdivision, 8000 texels
# to 99% (see README, Performance).
bench-gpu-detail: $(BIN)/bench-gpu | out
	$(BIN)/bench-gpu --detail -o out/bench-gpu-detail.ron
