# `make bench-renderpark`: hierarchical-solve against RenderPark's
# hierarchical Galerkin radiosity with clustering (the rpkCpp port), the
# issue's peer for the solve, both timed on this machine in one run, and
# both solutions' surfaces against a reference solve
# (bench/renderpark/bench_renderpark.py says how). A benchmark only: never
# part of `make test` or CI. rpkCpp (GPL-3; run, never shipped with this
# project) is cloned from RPK_REPO at RPK_COMMIT into $(RPK_DIR)/src, or
# taken from a checkout at RPK_SRC; a copy of it in
# $(RPK_DIR)/src-radiance, whose VRML writer keeps the radiance it solved
# for (RenderPark tone maps the colours it saves, to three digits), is
# built with cmake in $(RPK_DIR)/build-radiance. It needs cmake, a C++
# compiler and the OpenGL, GLU and GLUT headers (Debian: cmake g++
# freeglut3-dev libglu1-mesa-dev), which it installs when run as root on
# Debian. Writes $(RPK_OUT)/table.md (times: per program and setting the
# median time and links, and hierarchical-solve's time over rpk's) and
# $(RPK_OUT)/surfaces.md (each surface's mean radiosity against a solve at
# EPS $(RPK_REF_EPS)) and, where `make bench-peer`'s Mitsuba image exists
# (RPK_IMAGE_REF), $(RPK_OUT)/images.md (every solution's preview against
# it), printed too. About a minute once rpk is built.

RPK_REPO ?= https://github.com/OscarChavarro/rpkCpp.git
RPK_COMMIT ?= 37e5ff4eede5fd7444916eb06f0379db137fefc9
RPK_DIR ?= out/renderpark
RPK_SRC ?= $(RPK_DIR)/src
RPK_RADIANCE_SRC := $(RPK_DIR)/src-radiance
RPK_BIN := $(RPK_DIR)/build-radiance/rpk
# rpk's link-error thresholds (the issue's 3e-5 and 1e-4), the solve's
# EPS values (6e-4: every surface of seeds 1-8 within 0.7%, the README's
# RenderPark table) and the counted rounds (one warm-up more).
RPK_THRESHOLDS ?= 3e-5,1e-4
RPK_EPS ?= 6e-4
RPK_RUNS ?= 9
# More seeds whose solutions' images are averaged with the timed one's
# (comma-separated; empty: the timed seed's image alone).
RPK_IMAGE_SEEDS ?=
# The reference the surfaces are measured against: hierarchical-solve at
# this EPS (within 0.01% of EPS 1e-5 on every surface of the built-in
# Cornell box), solved once.
RPK_REF_EPS ?= 2.5e-5
# The path-traced image the previews are compared with, if it exists.
RPK_IMAGE_REF ?= $(OUT)/peer/reference.exr
RPK_OUT ?= $(OUT)/renderpark
RPK_PACKAGES := cmake g++ freeglut3-dev libglu1-mesa-dev

.PHONY: bench-renderpark

$(RPK_BIN):
	@if ! command -v cmake >/dev/null || [ ! -f /usr/include/GL/glut.h ] || [ ! -f /usr/include/GL/glu.h ]; then \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    echo "bench-renderpark: installing $(RPK_PACKAGES)"; apt-get install -y -q $(RPK_PACKAGES) >/dev/null; \
	  else echo "bench-renderpark: rpkCpp needs $(RPK_PACKAGES) (apt-get install them as root)" >&2; exit 2; fi; \
	fi
	@if [ ! -f $(RPK_SRC)/CMakeLists.txt ]; then \
	  git clone --quiet $(RPK_REPO) $(RPK_SRC) && git -C $(RPK_SRC) checkout --quiet $(RPK_COMMIT); \
	fi
	@# The Galerkin VRML writer: the radiance itself, not radianceToRgb's
	@# tone-mapped and clipped display colour, to nine digits, not three.
	rm -rf $(RPK_RADIANCE_SRC) && mkdir -p $(RPK_RADIANCE_SRC)
	tar -C $(RPK_SRC) --exclude=.git -cf - . | tar -C $(RPK_RADIANCE_SRC) -xf -
	sed -i -e 's/radianceToRgb(vertexRadiosity\[i\], &col);/col = vertexRadiosity[i];/' \
	  -e 's/"%.3g %.3g %.3g", color->r/"%.9g %.9g %.9g", color->r/' $(RPK_RADIANCE_SRC)/src/GALERKIN/GalerkinRadianceMethod.cpp
	@grep -q 'col = vertexRadiosity\[i\];' $(RPK_RADIANCE_SRC)/src/GALERKIN/GalerkinRadianceMethod.cpp && \
	  grep -q '"%.9g %.9g %.9g", color->r' $(RPK_RADIANCE_SRC)/src/GALERKIN/GalerkinRadianceMethod.cpp || \
	  { echo "bench-renderpark: $(RPK_SRC)/src/GALERKIN/GalerkinRadianceMethod.cpp is not rpkCpp $(RPK_COMMIT)'s: its VRML writer could not be made to keep the radiance" >&2; exit 2; }
	cmake -S $(RPK_RADIANCE_SRC) -B $(RPK_DIR)/build-radiance >/dev/null
	cmake --build $(RPK_DIR)/build-radiance -j $$(nproc)

# The surfaces' reference: one solve at RPK_REF_EPS, on every core.
$(RPK_OUT)/reference-$(RPK_REF_EPS).exr: $(BIN)/hierarchical-solve $(OUT)/params/hierarchical-solve.ron $(OUT)/params/clusters $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr $(CLUSTERS_EXR)
	@mkdir -p $(RPK_OUT)
	$(BIN)/hierarchical-solve --params $(OUT)/params/hierarchical-solve.ron --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr $(if $(CLUSTERS_EXR),--clusters $(CLUSTERS_EXR)) \
	  --eps $(RPK_REF_EPS) --seed 1 -o $@ --report $@.report.ron

bench-renderpark: $(BINS) $(BIN)/bench-surfaces $(RPK_BIN) $(OUT)/params/grid-gather.ron $(MITSUBA_XML) $(OUT)/params/hierarchical-solve.ron $(OUT)/params/clusters $(OUT)/mesh.exr $(OUT)/manifest.ron $(OUT)/surface.exr $(CLUSTERS_EXR) $(RPK_OUT)/reference-$(RPK_REF_EPS).exr
	python3 bench/renderpark/bench_renderpark.py --xml $(MITSUBA_XML) --rpk $(RPK_BIN) \
	  --thresholds $(RPK_THRESHOLDS) --eps $(RPK_EPS) --runs $(RPK_RUNS) --out $(RPK_OUT) $(if $(RPK_IMAGE_SEEDS),--image-seeds $(RPK_IMAGE_SEEDS)) \
	  --surfaces '$(BIN)/bench-surfaces --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --reference $(RPK_OUT)/reference-$(RPK_REF_EPS).exr' \
	  $(if $(wildcard $(RPK_IMAGE_REF)),--image-reference $(RPK_IMAGE_REF)) \
	  --preview '$(BIN)/grid-gather --params $(OUT)/params/grid-gather.ron --mode preview --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr' \
	  --compare '$(BIN)/compare --exclude-emitters --exclude-edges 2 --manifest $(OUT)/manifest.ron' \
	  --solve '$(BIN)/hierarchical-solve --params $(OUT)/params/hierarchical-solve.ron --mesh $(OUT)/mesh.exr --manifest $(OUT)/manifest.ron --surface $(OUT)/surface.exr $(if $(CLUSTERS_EXR),--clusters $(CLUSTERS_EXR))'
