# `make bench-mirror`: paper 004 Table 4.1's columns (triangles, elements or
# texels, shots, solver time) and the time spent on specular paths (t_spec)
# for scenes with mirrors, for hierarchical-solve (to its tolerance) and
# gpu-shoot (to 90% convergence, the paper's measure): McGuire's
# CornellBox-Mirror and a room with two facing mirrors
# (bench/assets/mirror/<scene>/scene.ron). Each scene runs through the
# ordinary pipelines with OUT=$(MIRROR_OUT)/<scene>, then bench-mirror
# tabulates the reports into $(MIRROR_OUT)/table.md (printed too). A
# benchmark only: never part of `make test`. About 8 minutes on 2 cores,
# most of it hierarchical-solve on the two-mirror room.
#
# `make bench-mirror-peer`: both solvers against Mitsuba 3 on the mirror
# box (make bench-peer with SCENE the box, gpu-shoot's preview and the
# full gather as further images, no sweep; PEER_* as for bench-peer).

MIRROR_SCENES ?= cornell-mirror two-mirrors
MIRROR_OUT ?= out/bench-mirror
# Further make variables for the scenes' runs (e.g. EPS=1e-3 GPU_TEXELS=8192).
MIRROR_FLAGS ?=
MIRROR_PEER_SCENE ?= bench/assets/mirror/cornell-mirror/scene.ron

.PHONY: bench-mirror bench-mirror-peer

$(BIN)/bench-mirror: FORCE
	@cargo build --release --quiet -p bench --bin bench-mirror

bench-mirror: $(BIN)/bench-mirror
	@for s in $(MIRROR_SCENES); do \
	  $(MAKE) --no-print-directory SCENE=bench/assets/mirror/$$s/scene.ron OUT=$(MIRROR_OUT)/$$s GPU_CONVERGENCE=0.9 $(MIRROR_FLAGS) \
	    $(MIRROR_OUT)/$$s/solution.exr $(MIRROR_OUT)/$$s/gpu/solution.exr || exit 1; \
	done
	$(BIN)/bench-mirror --dir $(MIRROR_OUT) -o $(MIRROR_OUT)/table.md $(MIRROR_SCENES)

bench-mirror-peer:
	$(MAKE) --no-print-directory SCENE=$(MIRROR_PEER_SCENE) PEER_SWEEP=0 \
	  PEER_ALSO='gpu-shoot=$$(OUT)/gpu/preview.exr full=$$(OUT)/final.exr' bench-peer
