// The kernel for avx2; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::fma3<xsimd::avx2>
#define PRINCIPLED_BRDF_ARCH_NS avx2
#include "kernel.hpp"
