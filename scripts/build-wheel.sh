#!/usr/bin/env bash
# `make wheel`: a portable (manylinux) wheel in dist/.
#
# pip builds the wheel without build isolation (scripts/install-deps.sh installs
# the build requirements) in scikit-build-core's build tree build/{wheel_tag},
# the one `pip install .` uses, so a rebuild compiles only what changed (the
# same lock as scripts/dev-install.sh keeps the two apart). The compile flags
# are CMakeLists.txt's: baseline x86-64 everywhere except the AVX2 and AVX-512
# kernel files, chosen at run time; a CPU flag in the cached global flags
# (e.g. CXXFLAGS=-march=native at the first configure) is refused here.
# auditwheel then checks the external symbols and sets the lowest manylinux tag
# the module satisfies (--plat auto); it grafts nothing, since the module needs
# only libc, libm, libstdc++ and libgcc_s, which every manylinux system provides.
set -euo pipefail
# shellcheck source-path=SCRIPTDIR source=_common.sh
source "$(dirname "$0")/_common.sh"  # repo root, $python, the build lock

raw=build/wheel-raw
rm -rf "$raw"
mkdir -p "$raw" dist
"$python" -m pip wheel -q --disable-pip-version-check --no-build-isolation --no-deps -w "$raw" .
wheels=("$raw"/principled_brdf-*.whl)
wheel=${wheels[0]}
name=$(basename "$wheel" .whl)   # principled_brdf-VERSION-PY-ABI-PLATFORM
tag=${name#*-*-}                 # PY-ABI-PLATFORM: scikit-build-core's {wheel_tag}

cache=build/$tag/CMakeCache.txt
if grep -E '^CMAKE_CXX_FLAGS(_RELEASE)?:STRING=.*-m(arch|avx|fma|sse[34]|bmi|popcnt|f16c)' "$cache"; then
  echo "build-wheel.sh: $cache has CPU-specific global flags (above); the wheel would not be portable." >&2
  echo "Unset CXXFLAGS and remove build/$tag, then run again." >&2
  exit 1
fi

"$python" -m auditwheel show "$wheel"
# Replace an earlier wheel of this version and Python, so `pip install dist/*.whl` finds one.
rm -f dist/"${name%-*}"-*.whl
"$python" -m auditwheel repair -w dist "$wheel"
ls -l dist/"${name%-*}"-*.whl
