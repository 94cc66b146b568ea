# The README's two set-up commands: `make demo` and `make test`.
# Each installs what it needs and no more (scripts/install-deps.sh's groups:
# the demo the build and matplotlib, the tests their own stack), then this package.
PYTHON ?= python3
export PYTHON

.PHONY: demo test install deps bench sanitize wheel docs check-neon

demo: install
	bash scripts/install-deps.sh demo
	$(PYTHON) -m principled_brdf demo

test: install
	bash scripts/install-deps.sh test browser neon
	$(PYTHON) -m pytest -q tests

install: deps
	bash scripts/dev-install.sh

# the build's requirements alone: the compiler, xsimd, Eigen, scikit-build-core, pybind11, numpy
deps:
	bash scripts/install-deps.sh build

# A portable manylinux wheel in dist/ (scripts/build-wheel.sh says how); `pip install dist/*.whl`
wheel: deps
	bash scripts/install-deps.sh wheel
	bash scripts/build-wheel.sh

# Google Benchmark executable (not part of the wheel); its results go to bench/results.json (not tracked)
bench: deps
	bash scripts/install-deps.sh bench
	cmake -S . -B build/bench -G Ninja -DCMAKE_BUILD_TYPE=Release -DPRINCIPLED_BRDF_BENCH=ON \
	  -Dpybind11_DIR="$$($(PYTHON) -c 'import pybind11; print(pybind11.get_cmake_dir())')"
	cmake --build build/bench --target principled_brdf_bench
	build/bench/bench/principled_brdf_bench --benchmark_min_time=0.2 --benchmark_repetitions=6 \
	  --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true \
	  --benchmark_out=bench/results.json --benchmark_out_format=json
	$(PYTHON) bench/summarize.py bench/results.json

# The extension under AddressSanitizer + UndefinedBehaviorSanitizer, running the
# bad-input, batch, sampling and fuzz tests (scripts/sanitize.sh says how).
sanitize: deps
	bash scripts/install-deps.sh test
	bash scripts/sanitize.sh

# The API reference from the docstrings (Sphinx, docs/api/), into build/docs; open build/docs/index.html
docs: install
	bash scripts/install-deps.sh docs
	$(PYTHON) -m sphinx -b html -W --keep-going -q -d build/docs/.doctrees docs/api build/docs

# The NEON kernel against the float64 reference: built for aarch64 into build/neon-check
# and run under qemu's emulation on x86-64 (scripts/check-neon.sh says how)
check-neon:
	bash scripts/check-neon.sh
