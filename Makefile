# The two commands of the README:  `make demo`  and  `make test`.
# Everything else here is a step of those two.
PYTHON ?= python3
VENV   := .venv
VPY    := $(VENV)/bin/python
JOBS   ?= 2
CPP_BUILD := build/cpp
CXX_SOURCES = $(shell git ls-files 'cpp/*.h' 'cpp/*.cc' 'python/bindings/*.h' 'python/bindings/*.cc' \
                'tests/cpp/*.cc' 'tests/cpp/*.h' 'examples/cpp_consumer/*.cc')
# With ccache installed, paths inside the checkout are hashed relative to it,
# so clones and worktrees of the project share compiled objects.
export CCACHE_BASEDIR ?= $(CURDIR)
PREFIX    := build/prefix

.PHONY: format demo test deps venv venv-dev install cpp cpp-test consumer-test py-test lint stubs bench fuzz clean sanitize
.PHONY: docs docs-shots wheel sanitize-ci

demo: install
	$(VPY) examples/demo.py

test: cpp-test consumer-test py-test lint sanitize-ci

deps:
	@bash scripts/install_deps.sh

# What the demo and the package need (the build tools, numpy, and the extras
# boxplus-calib uses); the test, lint and docs tools are venv-dev's. The venv
# does not see the system's site packages: only what is listed here.
DEMO_PKGS := "scikit-build-core>=0.10" "pybind11>=2.12" numpy matplotlib \
             "opencv-python-headless>=4.8,<5" pyyaml tqdm
DEV_PKGS  := pytest hypothesis scipy ruff pybind11-stubgen mypy sphinx myst-parser threadpoolctl \
             "ray>=2.9" "dask[distributed]>=2023.1" \
             "rosbags>=0.10"

venv: deps
	@test -x $(VPY) || $(PYTHON) -m venv $(VENV)
	@echo "venv: the packages the demo needs"
	@$(VPY) -m pip install -q --disable-pip-version-check $(DEMO_PKGS)

# Tests, lint, docs: pytest, hypothesis, scipy (references), ruff, mypy, the stub
# generator, Sphinx; solve_many's cluster tests (Ray, Dask), both BLAS thread controls,
# and rosbags (the camera–IMU tests write and read ROS 1/2 bags and MCAP files).
venv-dev: venv
	@echo "venv-dev: the test, lint and docs tools"
	@$(VPY) -m pip install -q --disable-pip-version-check $(DEV_PKGS)

# pip reuses build/<wheel tag>/, so a second install rebuilds only what changed.
install: venv
	@bash scripts/install_package.sh

cpp: deps
	cmake -S . -B $(CPP_BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
	cmake --build $(CPP_BUILD) -j$(JOBS)

cpp-test: cpp
	ctest --test-dir $(CPP_BUILD) --output-on-failure -j$(JOBS)

# Installs the C++ package and builds an outside project against it.
consumer-test: cpp
	cmake --install $(CPP_BUILD) --prefix $(CURDIR)/$(PREFIX) >/dev/null
	cmake -S examples/cpp_consumer -B build/consumer -G Ninja \
	    -DCMAKE_PREFIX_PATH=$(CURDIR)/$(PREFIX) >/dev/null
	cmake --build build/consumer -j$(JOBS)
	./build/consumer/consumer

py-test: install venv-dev
	$(VPY) -m pytest -q

# The rule sets and the mypy settings are in pyproject.toml. mypy reads the
# committed stub python/boxplus/_core.pyi, so it needs no built extension.
lint: venv-dev
	$(VPY) -m ruff check --no-cache python tests examples bench docs
	$(VPY) -m mypy python/boxplus examples
	clang-format --dry-run -Werror $(CXX_SOURCES)
	$(VPY) -m sphinx -E -W --keep-going -q -b html docs build/docs

# The documentation site in build/docs (Sphinx autodoc over the installed
# package, the tutorials of docs/tutorials); every warning is an error. `lint`
# builds it too, after py-test has installed the package.
docs: install venv-dev
	$(VPY) -m sphinx -E -W --keep-going -q -b html docs build/docs

# Every page of the site in a real headless browser, as PNGs to look at (needs chromium).
docs-shots: docs
	bash scripts/docs_screenshots.sh

# A self-contained wheel in build/wheelhouse (scripts/build_wheel.sh: repaired
# by auditwheel, one BLAS), then its test in a fresh venv (tests/python/test_wheel.py).
# --noconftest: the test step needs no boxplus in this venv (the wheel is tested in its
# own); tests/python/test_wheel.py checks that it runs so.
wheel: venv-dev
	bash scripts/build_wheel.sh
	BOXPLUS_TEST_WHEEL=1 $(VPY) -m pytest -q --noconftest -p no:cacheprovider tests/python/test_wheel.py

# clang-format (.clang-format: Google, 100 columns) over every C++ file.
format:
	clang-format -i $(CXX_SOURCES)

# Regenerates the committed stub of the extension from the installed module
# (tests/python/test_stubs.py fails when the two differ).
stubs: install venv-dev
	rm -rf build/stubs
	$(VPY) -m pybind11_stubgen boxplus._core -o build/stubs
	cp build/stubs/boxplus/_core.pyi python/boxplus/_core.pyi

bench: install
	$(VPY) -m pip install -q --disable-pip-version-check gtsam g2opy "opencv-python-headless<5" || true
	$(VPY) bench/run_all.py

# ASan + UBSan: the library, the C++ tests and the tools in build/asan, the
# extension installed into build/asan-site; ctest and the Python suite run
# under them (the Python interpreter is not instrumented, so the sanitizer
# runtimes are preloaded; CPython's own allocations are not leak-checked).
# -O1 -g1: the optimisation the ASan documentation suggests for usable speed,
# and line tables only, all the reports' file:line need. The pip build of the
# extension uses the same flags.
ASAN_SITE  := build/asan-site
ASAN_FLAGS := -O1 -g1 -DNDEBUG
ASAN_ENV   := ASAN_OPTIONS=detect_leaks=0:abort_on_error=0:strict_string_checks=1 \
              UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
sanitize: venv-dev
	cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DBOXPLUS_SANITIZE=ON \
	    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$(ASAN_FLAGS)" >/dev/null
	cmake --build build/asan -j$(JOBS)
	$(ASAN_ENV) ctest --test-dir build/asan --output-on-failure -j$(JOBS)
	$(VPY) -m pip install -q --disable-pip-version-check --no-build-isolation --no-deps \
	    --upgrade --target $(ASAN_SITE) -C build-dir=build/asan-wheel \
	    -C cmake.build-type=RelWithDebInfo -C cmake.define.BOXPLUS_SANITIZE=ON \
	    -C "cmake.define.CMAKE_CXX_FLAGS_RELWITHDEBINFO=$(ASAN_FLAGS)" .
	$(ASAN_ENV) LD_PRELOAD="$$(gcc -print-file-name=libasan.so) $$(gcc -print-file-name=libubsan.so)" \
	    PYTHONPATH=$(CURDIR)/$(ASAN_SITE) PATH=$(CURDIR)/$(ASAN_SITE)/bin:$$PATH \
	    $(VPY) -m pytest -q -p no:cacheprovider
# The sanitizer part of CI (`make test`): the C++ tests and the fuzz regressions
# (tests/data/fuzz_regressions, through boxplus-g2o) under ASan + UBSan, and the
# tests that assemble the normal equations or solve on threads under TSan. Only
# the C++ tests and the tool are built, at -O1, so that it fits CI's time.
SAN_BUILD = cmake -S . -B build/$(1) -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	    -DBOXPLUS_SANITIZE=$(2) -DBOXPLUS_BUILD_PYTHON=OFF "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$(ASAN_FLAGS)" \
	    >/dev/null && cmake --build build/$(1) -j$(JOBS) --target boxplus_tests boxplus-g2o
TSAN_TESTS := *Thread*:*Concurrent*:NormalEquations.*
sanitize-ci: deps
	$(call SAN_BUILD,asan-ci,address)
	$(ASAN_ENV) OPENBLAS_NUM_THREADS=1 ./build/asan-ci/boxplus_tests --gtest_brief=1
	bash scripts/replay_fuzz_regressions.sh build/asan-ci/boxplus-g2o
	$(call SAN_BUILD,tsan-ci,thread)
	TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 OPENBLAS_NUM_THREADS=1 \
	    ./build/tsan-ci/boxplus_tests --gtest_brief=1 '--gtest_filter=$(TSAN_TESTS)'

# 10⁶ seeded mutations of the g2o files through the loader (and a sample through
# boxplus-g2o); bad outcomes are kept in tests/data/fuzz_regressions/.
fuzz: install
	OPENBLAS_NUM_THREADS=1 PYTHONPATH=tests $(VPY) -m harness.fuzz --cases 1000000 --seed 2 --jobs $(JOBS) \
	    --cli $(VENV)/bin/boxplus-g2o --cli-every 1000

clean:
	rm -rf build $(VENV)
