# proxseg: the two commands of the README.
#   make demo   install what is missing (apt), build, segment the built-in synthetic scene
#               (and, when ../shared/data is present, a real mOSD scene, and recognise the
#               objects of a YCB-Video frame from a database of three models it builds)
#   make test   install what is missing, build, run every test (ctest)
#   make test-sanitize  the tests of readers, database, batches, memory and threads built with
#               AddressSanitizer and UndefinedBehaviorSanitizer
#   make test-numerics  two more builds (no vectorisation or fused multiply-add; AVX-512) answer
#               as the default build does on mOSD learn, YCB-Video and the generated sets
#   make package  the Debian packages: one per library (libproxseg-core0.2, -io0.2,
#               -recognition0.2, -eval0.2), libproxseg-dev (headers, CMake and pkg-config
#               files), proxseg (the CLI, man page, completion), python3-proxseg and proxseg-doc
#   make docs   the C++ (Doxygen) and Python API references, and docs/parameters.md
#   make test-pip  `pip install .` into a fresh virtual environment, import, segment a scene
#   make fuzz   libFuzzer on every reader, FUZZ_TIME seconds each (docs/robustness.md)
#   make bench  install what is missing (PCL too), build, run every benchmark (docs/results.md)
#   make bench-seg  only the segmentation benchmark: proxseg vs PCL on mOSD learn and the
#                   generated clutter, piles and occlusion sets ($(BUILD)/seg-dev, made when
#                   missing)
#   make bench-ablation  what each segmentation stage buys: seg_cv with each stage off
#                   (bench/seg_ablation.json) on mOSD learn and the same generated sets,
#                   cross-validated folds
#   make bench-mem  only the memory benchmark: peak RSS per frame, 64-view recognition, batch growth
#   make bench-rec  only the recognition benchmark: the paper's Tables 2-3 and ROC, with the
#                   Open3D (RANSAC, FGR), PCL and OpenCV PPF peers
#   make bench-scenes  only the scene benchmark: segmentation + recognition end to end on
#                   generated tabletops with known, look-alike and unknown objects (dev and
#                   report splits), proxseg vs PCL Euclidean clusters + Open3D
#   make bench-objects  only the object folds: recognition on objects left out of every choice
#                   (object_set.hpp), proxseg and, on two folds, the PCL + Open3D peer
#   make bench-python  only the Python module's overhead: segment() from Python against C++, and a
#                   100-frame loop in one process against 100 CLI calls
#   make bench-dbscale  only the database-size benchmark: recognition cost and accuracy with
#                   64-16,384 views (LINEMOD + distractors) in a database file: opening, one
#                   process per question, shortlist against every view
#   make bench-batch  only batch work: segment --batch (all cores, one thread), proxseg.dask and one
#                   CLI call per frame on 100 frames; bytes per --outputs choice; RSS over 2,000
#                   frames (fails above 5 % growth)
#   make bench-view  only the pages of `proxseg view`: sizes, time to open and to turn, in
#                   headless Chromium, for 55 real frames and batch logs of 1,000-1,000,000 frames
#   make bench-real  only the real YCB-Video scenes, each video one fold: segmented, named, pose,
#                   other names, leave-one-out, s/frame and the sensor's figures, proxseg's rules
#                   chosen on one fold and scored on the other, PCL LCCP, Open3D and OpenCV PPF
BUILD ?= build
# The Python the module is built for (python/CMakeLists.txt prefers Debian's).
PYTHON ?= /usr/bin/python3
JOBS ?= $(shell nproc)
DATA ?= ../shared/data
DEMO_OUT ?= demo-out
DEMO_OBJECTS = 009_gelatin_box 025_mug 061_foam_brick
MAKEFLAGS += --no-print-directory

.PHONY: all deps deps-bench configure build demo test build-sanitize test-sanitize test-numerics test-pip package docs fuzz bench bench-seg bench-ablation seg-dev bench-rec bench-mem bench-scenes bench-objects bench-dbscale bench-python bench-batch bench-view bench-real format clean

all: build

deps:
	@bash scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPROXSEG_DATA_DIR=$(abspath $(DATA)) >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	@mkdir -p $(DEMO_OUT)
	@$(BUILD)/proxseg synth -o $(DEMO_OUT)/synth-scene.pcd
	@$(BUILD)/proxseg segment $(DEMO_OUT)/synth-scene.pcd -o $(DEMO_OUT)/synth
	@if [ -f $(DATA)/mosd/learn/learn0.pcd ]; then \
	  $(BUILD)/proxseg segment $(DATA)/mosd/learn/learn0.pcd -o $(DEMO_OUT)/learn0; fi
	@# Recognition [paper 3.4]: a database of three YCB-Video models, then a real frame.
	@if [ -d $(DATA)/ycbv/frames ]; then \
	  rm -rf $(DEMO_OUT)/ycbv-db; \
	  for n in $(DEMO_OBJECTS); do \
	    $(BUILD)/proxseg db add $(DEMO_OUT)/ycbv-db -q --name $$n \
	      --xyz $(DATA)/ycbv/models/$$n/points.xyz >/dev/null || exit 1; done; \
	  echo "recognising YCB-Video frame 000004 with $(DEMO_OUT)/ycbv-db ($(DEMO_OBJECTS)):"; \
	  $(BUILD)/proxseg recognize -q --db $(DEMO_OUT)/ycbv-db \
	    --colour $(DATA)/ycbv/frames/000004-color.png --depth $(DATA)/ycbv/frames/000004-depth.png \
	    --meta $(DATA)/ycbv/frames/000004-meta.json -o $(DEMO_OUT)/ycbv-000004 \
	    | awk 'NR == 1 || $$4 != "unknown"'; fi
	@echo "demo outputs (labelled PCD, picture, JSON report) are in $(DEMO_OUT)/:"
	@ls -1 $(DEMO_OUT)/*.png $(DEMO_OUT)/*.json | sed 's/^/  /'

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

# Results that do not depend on the processor (docs/method.md, "Numerics"): the library and the
# CLI built twice more, and their answers compared with the default build's
# (scripts/compare-builds.py) on mOSD learn (both presets), the generated sets ($(SEGDEV)) and both
# YCB-Video scenes against the 21 models. "scalar": Eigen without vectorisation, no fused
# multiply-add, and at run time glibc's and OpenCV's dispatch held to SSE (a processor without
# AVX); "v4": -march=x86-64-v4 (AVX-512 and FMA in Eigen's kernels and every loop the compiler
# vectorises; the libraries' own -ffp-contract=off keeps a * b + c uncontracted). GCC 12 warns
# inside its AVX-512 intrinsics as Eigen uses them (masked loads of a Vector3d in umeyama): false
# positives, silenced in that build only.
NUMERICS = $(BUILD)/numerics
NUMERICS_CONFIG = -DCMAKE_BUILD_TYPE=Release -DPROXSEG_BUILD_TESTS=OFF -DPROXSEG_BUILD_BENCH=OFF \
  -DPROXSEG_PYTHON=OFF -DPROXSEG_DATA_DIR=$(abspath $(DATA))
SCALAR_RUN = --env scalar=GLIBC_TUNABLES=glibc.cpu.hwcaps=-AVX,-AVX2,-FMA,-AVX512F \
  --env scalar=OPENCV_CPU_DISABLE=AVX,AVX2,FMA3,AVX512F,AVX512-SKX,AVX512-COMMON,AVX512CD,AVX512BW,AVX512DQ,AVX512VL
test-numerics: build seg-dev
	@cmake -S . -B $(BUILD)-scalar $(NUMERICS_CONFIG) \
	  -DCMAKE_CXX_FLAGS="-DEIGEN_DONT_VECTORIZE -ffp-contract=off" >/dev/null
	@cmake --build $(BUILD)-scalar -j $(JOBS) --target proxseg_cli
	@cmake -S . -B $(BUILD)-v4 $(NUMERICS_CONFIG) -DCMAKE_CXX_FLAGS="-march=x86-64-v4 -Wno-maybe-uninitialized -Wno-array-bounds" >/dev/null
	@cmake --build $(BUILD)-v4 -j $(JOBS) --target proxseg_cli
	@rm -rf $(NUMERICS)
	@$(PYTHON) scripts/compare-builds.py --data $(DATA) --generated $(SEGDEV) --work $(NUMERICS) \
	  $(SCALAR_RUN) default=$(BUILD) scalar=$(BUILD)-scalar v4=$(BUILD)-v4

# The Debian packages (CPack; CMakeLists.txt says how they are split) with the API references
# built first for proxseg-doc: $(BUILD)/<package>_<version>-1_<arch>.deb, installable with
# `apt install ./$(BUILD)/<package>_*.deb`; cpack's log in $(BUILD)/cpack.log. The version is
# project()'s in CMakeLists.txt.
VERSION = $(shell sed -n 's/^project.proxseg VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
package: build
	@cmake --build $(BUILD) --target proxseg_docs >/dev/null
	@cd $(BUILD) && { cpack -G DEB >cpack.log 2>&1 || { cat cpack.log; exit 1; }; }
	@ls -1 $(BUILD)/*_$(VERSION)-*_*.deb

# `pip install .` as a Python user does it: a fresh virtual environment (system site packages,
# for numpy and Debian's setuptools; no package index), the module built by setup.py with CMake
# (static libraries: about 10 minutes on 2 cores), then imported and run on a real scene.
test-pip: deps
	@rm -rf $(BUILD)/pip-venv && /usr/bin/python3 -m venv --system-site-packages $(BUILD)/pip-venv
	@$(BUILD)/pip-venv/bin/pip install -q --no-build-isolation --no-index .
	@cd $(BUILD) && pip-venv/bin/python -c "import proxseg, sys; \
	  r = proxseg.segment('$(abspath $(DATA))/mosd/learn/learn0.pcd'); \
	  assert 'pip-venv' in proxseg.__file__ and len(r.candidates) == 2, (proxseg.__file__, r); \
	  print('pip install .:', proxseg.__file__, r)"

# The references: C++ (Doxygen, public headers, warnings are errors) into $(BUILD)/docs/cpp,
# Python (pydoc) into $(BUILD)/docs/python, and docs/parameters.md from the parameter table.
# The target proxseg_docs (CMakeLists.txt) makes both; proxseg-doc installs them.
docs: build
	@cmake --build $(BUILD) --target proxseg_docs >/dev/null
	@$(BUILD)/proxseg params --markdown > docs/parameters.md
	@echo "API reference: $(BUILD)/docs/cpp/html/index.html, $(BUILD)/docs/python/proxseg.html"

# The tests of what the sanitizers can find (tests/CMakeLists.txt, those marked SANITIZE:
# readers, database, batches, memory and file-system faults, threads, the pages' writers) under
# ASan + UBSan (gcc): any memory error, leak or undefined behaviour fails the test it happens in.
# Its own build tree, without the benchmarks, the Python module and the other tests, with a
# static library (the install test, which needs the shared one, runs in `make test`); -O1 -g1
# compiles in half the time of -O2 -g and keeps file and line in the sanitizers' reports.
SAN_BUILD ?= build-sanitize
SAN_FLAGS = -O1 -g1 -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
build-sanitize: deps
	@cmake -S . -B $(SAN_BUILD) -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="$(SAN_FLAGS)" \
	  -DCMAKE_C_FLAGS_SANITIZE="$(SAN_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS_SANITIZE="-fsanitize=address,undefined" \
	  -DPROXSEG_BUILD_BENCH=OFF -DPROXSEG_SHARED=OFF -DPROXSEG_PYTHON=OFF -DPROXSEG_DATA_DIR=$(abspath $(DATA)) >/dev/null
	@cmake --build $(SAN_BUILD) -j $(JOBS)

test-sanitize: build-sanitize
	@cd $(SAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure -j $(JOBS)

# libFuzzer on every reader (clang-14): FUZZ_TIME seconds per harness, FUZZ_JOBS at once.
FUZZ_TIME ?= 1800
fuzz:
	@bash scripts/install-deps.sh --fuzz
	@FUZZ_TIME=$(FUZZ_TIME) DATA=$(DATA) bash scripts/fuzz.sh

# Benchmarks need PCL and OpenCV contrib (the peers); installed here, never for the library or
# the tests.
deps-bench:
	@bash scripts/install-deps.sh --bench

# The steps every bench recipe shares: $(call bench_build,TARGETS) builds the targets;
# $(call bench_results,SECTION,FILE,NOTE) regenerates SECTION of docs/results.md from FILE and says
# so, NOTE after (where the rest of the outputs are).
# $(call bench_update,SECTION,FILE) only regenerates (NOTE: use $(comma) for a comma).
comma := ,
bench_build = @cmake --build $(BUILD) -j $(JOBS) --target $(1)
bench_update = @bash scripts/update-results.sh docs/results.md $(1) $(2)
define bench_results
$(call bench_update,$(1),$(2))
@echo "docs/results.md ($(1)) regenerated$(3)"
endef

bench: bench-seg bench-ablation bench-rec bench-mem bench-scenes bench-objects bench-dbscale bench-python bench-batch bench-view bench-real

# The generated development scenes of the segmentation: clutter (60), piles and occlusion (30
# each), seeds from 1 (docs/clutter.md); made once.
SEGDEV = $(BUILD)/seg-dev
seg-dev: configure
	@cmake --build $(BUILD) -j $(JOBS) --target proxseg_cli
	@mkdir -p $(SEGDEV)
	@for k in clutter:60 piles:30 occlusion:30; do kind=$${k%:*} n=$${k#*:}; \
	  [ -f $(SEGDEV)/$$kind-0$$n.pcd ] || $(BUILD)/proxseg synth --clutter --kind $$kind \
	    --count $$n --models $(DATA)/lmo/models -o $(SEGDEV) > /dev/null; done

bench-seg: deps-bench configure seg-dev
	$(call bench_build,seg_bench proxseg_cli)
	@mkdir -p $(BUILD)/bench-out
	@$(BUILD)/bench/seg_bench --data $(DATA)/mosd/learn --clutter $(SEGDEV) \
	  --methods "proxseg paper,proxseg default,PCL LCCP,PCL plane + Euclidean" \
	  --out $(BUILD)/bench-out/segmentation.md --csv $(BUILD)/bench-out/segmentation.csv
	$(call bench_results,segmentation,$(BUILD)/bench-out/segmentation.md,; per-scene CSV in $(BUILD)/bench-out/)

# What each segmentation stage buys: seg_cv with each stage off in turn (bench/seg_ablation.json)
# on mOSD learn and the generated sets, cross-validated folds.
bench-ablation: configure seg-dev
	$(call bench_build,seg_cv)
	@mkdir -p $(BUILD)/bench-out
	@$(BUILD)/bench/seg_cv --data $(DATA)/mosd/learn --clutter $(SEGDEV) --threads 2 \
	  --grid bench/seg_ablation.json --out $(BUILD)/bench-out/ablation.md \
	  --title "Segmentation: what each stage buys (each off in turn, cross-validated)"
	$(call bench_results,ablation,$(BUILD)/bench-out/ablation.md,)

# Peak RSS of one frame and of a 64-view recognition; RSS over a 100-frame batch (no growth).
bench-mem: configure
	$(call bench_build,proxseg_cli mem_bench)
	@mkdir -p $(BUILD)/bench-out
	@$(BUILD)/bench/mem_bench --cli $(BUILD)/proxseg --data $(DATA) --out $(BUILD)/bench-out/memory.md \
	  --json $(BUILD)/bench-out/memory.json
	$(call bench_results,memory,$(BUILD)/bench-out/memory.md,)

# The paper's recognition experiments (Tables 2-3, ROC) with the peers: about 45 min on 2 cores.
REC_OUT = $(BUILD)/bench-out/rec
bench-rec: deps-bench configure
	$(call bench_build,rec_bench)
	@$(BUILD)/bench/rec_bench --models $(DATA)/lmo/models --views 8 --tests 2241 --seed 1 \
	  -o $(REC_OUT)
	@mkdir -p docs/img
	@cp $(REC_OUT)/roc.png docs/img/rec-roc.png && cp $(REC_OUT)/pr.png docs/img/rec-pr.png
	@{ head -n 1 $(REC_OUT)/summary.md; \
	  printf '\nAt commit %s; every output in `%s/`.\n' "$$(git rev-parse --short HEAD 2>/dev/null)" "$(REC_OUT)"; \
	  tail -n +2 $(REC_OUT)/summary.md; \
	  printf '\n![ROC](img/rec-roc.png)\n\n![Precision-recall per occlusion](img/rec-pr.png)\n'; \
	} > $(REC_OUT)/section.md
	$(call bench_results,recognition,$(REC_OUT)/section.md,; tables$(comma) CSV and plots in $(REC_OUT)/)

# Scene recognition end to end (scene_eval.hpp): 20 development + 20 report scenes through
# proxseg and the PCL + Open3D peer: about 1.5-2 h on 2 shared cores (3-4 min per scene).
SCENES_OUT = $(BUILD)/bench-out/scenes
bench-scenes: deps-bench configure
	$(call bench_build,scene_bench)
	@$(BUILD)/bench/scene_bench --models $(DATA)/lmo/models -o $(SCENES_OUT)
	$(call bench_results,scenes,$(SCENES_OUT)/scenes.md,; per-prediction and per-object CSV in $(SCENES_OUT)/)

# Recognition on objects it was never tuned on (object_set.hpp, docs/method.md "Recognition that
# generalises"): 13 object folds in two halves, 2 dev + 2 report scenes each, then the PCL + Open3D
# peer beside proxseg on the first fold of each half (1 + 1 scenes): about 40 min on 2 cores.
OBJECTS_OUT = $(BUILD)/bench-out/objects
OBJECTS_ARGS = --set objects --models $(DATA)/lmo/models --ycbv $(DATA)/ycbv \
  --textured $(DATA)/ycb_textured
bench-objects: deps-bench configure
	$(call bench_build,scene_bench)
	@$(BUILD)/bench/scene_bench $(OBJECTS_ARGS) --fold-scenes 2 --peers none -o $(OBJECTS_OUT)
	$(call bench_update,objects,$(OBJECTS_OUT)/scenes.md)
	@$(BUILD)/bench/scene_bench $(OBJECTS_ARGS) --max-folds 1 --fold-scenes 1 --peers all \
	  -o $(OBJECTS_OUT)-peer
	$(call bench_update,objects-peer,$(OBJECTS_OUT)-peer/scenes.md)
	@echo "docs/results.md (objects, objects-peer) regenerated; CSV in $(OBJECTS_OUT)*/"

# Recognition against database size (db_scale_bench): 64, 512, 4,096 and 16,384 views, each
# stored in a database file: 200 tests in process with the default shortlist, 40 aligning every
# view (up to 512 views), 8 `proxseg recognize --object` processes and the file's opening per
# size: about 35 min on 2 shared cores (rendering 16,384 views is most of it). Needs no PCL.
DBSCALE_OUT = $(BUILD)/bench-out/dbscale
bench-dbscale: configure
	$(call bench_build,db_scale_bench proxseg_tools)
	@$(BUILD)/bench/db_scale_bench --models $(DATA)/lmo/models --sizes 64,512,4096,16384 \
	  --tests 200 --all-tests 40 --all-max-views 512 --process-tests 8 --seed 1 -o $(DBSCALE_OUT)
	$(call bench_results,dbscale,$(DBSCALE_OUT)/dbscale.md,; every object and row in $(DBSCALE_OUT)/dbscale.json)

# The Python module's overhead against the C++ library and the CLI (bench/python_bench.py):
# a few minutes.
bench-python: configure
	$(call bench_build,_proxseg segment_loop proxseg_cli)
	@$(PYTHON) bench/python_bench.py --build $(BUILD) --data $(DATA) --out $(BUILD)/bench-out
	$(call bench_results,python,$(BUILD)/bench-out/python.md,; raw figures in $(BUILD)/bench-out/python.json)

# Batch work (bench/batch_bench.py): throughput of segment --batch (all cores; --threads 1),
# proxseg.dask (2 workers) and one CLI call per frame on the same 100 frames (mOSD + YCB-Video
# pairs), bytes written per --outputs choice, RSS over a 2,000-frame batch (fails above 5 %
# growth), the cost of 100k frames on N workers: about 10 min on 2 cores.
bench-batch: configure
	$(call bench_build,_proxseg proxseg_cli)
	@$(PYTHON) bench/batch_bench.py --build $(BUILD) --data $(DATA) --out $(BUILD)/bench-out
	$(call bench_results,batch,$(BUILD)/bench-out/batch.md,; raw figures in $(BUILD)/bench-out/batch.json)

# The pages of `proxseg view` (bench/view_bench.py) in headless Chromium: bytes, time to the first
# frame drawn and per frame of a turn, for the 45 mOSD scenes and 10 YCB-Video recognitions, and
# the batch page of generated logs of 1,000-1,000,000 frames; fails when a page misses issue 35's
# limits (3 MB, 2 s; 3 s for 10,000 frames). A few minutes.
bench-view: configure
	$(call bench_build,proxseg_cli)
	@$(PYTHON) bench/view_bench.py --build $(BUILD) --data $(DATA) --out $(BUILD)/bench-out
	$(call bench_results,view,$(BUILD)/bench-out/view.md,; raw figures in $(BUILD)/bench-out/view.json)

# Real YCB-Video scenes, each video one fold (bench/real_bench.cpp): proxseg's variants of
# bench/real_grid.json chosen on one fold and reported on the other, leave-one-out databases,
# PCL LCCP and the Open3D and OpenCV PPF peers on the same frames. About 15 min on 2 cores.
REAL_OUT = $(BUILD)/bench-out/real
bench-real: deps-bench configure
	$(call bench_build,real_bench)
	@$(BUILD)/bench/real_bench --ycbv $(DATA)/ycbv --grid bench/real_grid.json -o $(REAL_OUT)
	$(call bench_results,real,$(REAL_OUT)/real.md,; per-object CSV in $(REAL_OUT)/)

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

clean:
	rm -rf $(BUILD) $(DEMO_OUT)
