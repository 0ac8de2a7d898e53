# proxseg: the two commands of the README.
#   make demo   install what is missing (apt), build, segment the built-in synthetic scene
#               (and a real mOSD scene when ../shared/data is present)
#   make test   install what is missing, build, run every test (ctest)
BUILD ?= build
JOBS ?= $(shell nproc)
DATA ?= ../shared/data
DEMO_OUT ?= demo-out
MAKEFLAGS += --no-print-directory

.PHONY: all deps configure build demo test format clean

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
	@echo "demo outputs (labelled PCD, picture, JSON report) are in $(DEMO_OUT)/:"
	@ls -1 $(DEMO_OUT)/*.png $(DEMO_OUT)/*.json | sed 's/^/  /'

test: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

format:
	@clang-format -i include/proxseg/*.hpp src/*.cpp src/*.hpp apps/*.cpp tests/*.cpp bench/*.cpp

clean:
	rm -rf $(BUILD) $(DEMO_OUT)
