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
[[ -e build/neon-check/neon_check ]] || echo "building the NEON check (the kernel's parts take a few minutes)"
make -s -j2 -C build/neon-check -f "$PWD/cpp/check/neon_check.mk" ROOT="$PWD" CXX="$compiler"

# The kernel divides and takes square roots exactly (kernel_neon.cpp): no
# reciprocal or reciprocal-square-root estimates (or their Newton steps) in it.
for object in build/neon-check/kernel_neon_part*.o; do
  "$objdump" -d --no-show-raw-insn "$object"
done >build/neon-check/kernel_neon.s
estimates=$(grep -cE '\s(frecpe|frecps|frsqrte|frsqrts)\s' build/neon-check/kernel_neon.s || true)
if ((estimates)); then
  echo "FAIL kernel_neon_part*.o: $estimates reciprocal estimate instructions (frecpe, frecps, frsqrte, frsqrts)"
  exit 1
fi
echo "ok   kernel_neon_part*.o: no reciprocal estimate instructions (frecpe, frecps, frsqrte, frsqrts)"
"${runner[@]}" build/neon-check/neon_check
