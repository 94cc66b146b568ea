#!/usr/bin/env bash
# The NEON kernel (cpp/src/kernel_neon.cpp) against the float64 reference
# (docs/validation.md, "On ARM"): builds cpp/check/neon_check.cpp with the
# kernels for aarch64 into build/neon-check (incrementally) and runs it, under
# qemu's user-mode emulation on another machine. Installs what it needs
# (scripts/install-deps.sh neon). Exits non-zero on a failure.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

bash scripts/install-deps.sh neon
if [[ $(uname -m) == aarch64 ]]; then
  compiler=g++
  objdump=objdump
  runner=()
else
  compiler=aarch64-linux-gnu-g++
  objdump=aarch64-linux-gnu-objdump
  runner=(qemu-aarch64)
fi

mkdir -p build/neon-check
# one compiler at a time: the kernel file alone takes minutes and 2 GB
[[ -e build/neon-check/neon_check ]] || echo "building the NEON check (the kernel file takes about 10 minutes)"
make -s -j1 -C build/neon-check -f "$PWD/cpp/check/neon_check.mk" ROOT="$PWD" CXX="$compiler"

# The kernel divides and takes square roots exactly (kernel_neon.cpp): no
# reciprocal or reciprocal-square-root estimates (or their Newton steps) in it.
"$objdump" -d --no-show-raw-insn build/neon-check/kernel_neon.o >build/neon-check/kernel_neon.s
estimates=$(grep -cE '\s(frecpe|frecps|frsqrte|frsqrts)\s' build/neon-check/kernel_neon.s || true)
if ((estimates)); then
  echo "FAIL kernel_neon.o: $estimates reciprocal estimate instructions (frecpe, frecps, frsqrte, frsqrts)"
  exit 1
fi
echo "ok   kernel_neon.o: no reciprocal estimate instructions (frecpe, frecps, frsqrte, frsqrts)"
"${runner[@]}" build/neon-check/neon_check
