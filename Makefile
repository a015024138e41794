# fdml_localization: the two commands.
#   make test   install what is missing, build in a private catkin workspace, run every test
#   make demo   install, build, and run the headless kidnapped-robot demo (RVIZ=1 opens rviz)
# Other targets: make deps | build | bench | verify | fuzz | test-asan | clean
#   make verify     the whole verification suite (scripts/verify.sh; figures in docs/BENCHMARKS.md)
#   make fuzz       the fuzz suite at full size (FUZZ_CASES cases, default 100000; docs/BENCHMARKS.md)
#   make test-asan  unit tests and the fuzz suite under AddressSanitizer + UBSan (workspace ws-asan/)
SHELL := /bin/bash
WS ?= $(CURDIR)/ws
RVIZ ?= 0
export WS

.PHONY: all deps build test demo bench verify fuzz test-asan clean

all: build

deps:
	@bash scripts/install_deps.sh

build: deps
	@bash scripts/build.sh

test: deps
	@bash scripts/run_tests.sh

demo: build
	@RVIZ=$(RVIZ) bash scripts/demo.sh

bench: build
	@bash scripts/bench.sh

verify: build
	@bash scripts/verify.sh

fuzz: deps
	@bash scripts/fuzz.sh

test-asan: deps
	@bash scripts/test_asan.sh

clean:
	rm -rf $(WS) $(CURDIR)/ws-asan
