#!/usr/bin/env bash
# `make sanitize`: builds the extension with AddressSanitizer and
# UndefinedBehaviorSanitizer (-O1, its own build folder build/sanitize) and runs
# the bad-input (regressions and fuzz included), batch-API and SIMD-sampling tests
# under it.
#
# The Python interpreter is not instrumented, so the ASan runtime must be loaded
# first: LD_PRELOAD=$(g++ -print-file-name=libasan.so) (and libubsan.so), with
# leak detection off (the interpreter keeps its arenas to the end). The AVX-512
# kernel is compiled only where this CPU can run it: an instrumented build of it
# takes far longer than the others, and it could not be tested elsewhere.
set -euo pipefail
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
build=build/sanitize
avx512=OFF
grep -qw avx512bw /proc/cpuinfo 2>/dev/null && avx512=ON

start=$(date +%s)
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DPRINCIPLED_BRDF_SANITIZE=ON \
  -DPRINCIPLED_BRDF_AVX512="$avx512" -DPython_EXECUTABLE="$(command -v "$python")" \
  -Dpybind11_DIR="$("$python" -c 'import pybind11; print(pybind11.get_cmake_dir())')" >/dev/null
cmake --build "$build" --target _core
echo "sanitizer build: $(( $(date +%s) - start )) s (AVX-512 kernel: $avx512)"

# A package folder holding this checkout's Python sources and the instrumented module.
package="$build/package/principled_brdf"
rm -rf "$build/package"
mkdir -p "$package"
cp python/principled_brdf/*.py "$package/"
cp "$build"/_core*.so "$package/"

export LD_PRELOAD="$(g++ -print-file-name=libasan.so) $(g++ -print-file-name=libubsan.so)"
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
root=$PWD
export PYTHONPATH="$root/$build/package"
cd tests  # so that the installed package is not the one imported
"$python" -c "import principled_brdf, sys; assert principled_brdf.__file__.startswith('$root/$build'), principled_brdf.__file__"
# the SIMD sampler's chi-square tests (10^6 samples each) are left to the ordinary run
"$python" -m pytest -q -p no:cacheprovider bad_input api/test_batch_api.py sampling/test_simd_sampler.py \
  -k "not chi_square"
echo "sanitizer run: clean ($(( $(date +%s) - start )) s in all)"
