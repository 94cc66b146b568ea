// The kernel for avx512; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::avx512bw
#define PRINCIPLED_BRDF_ARCH_NS avx512
#include "kernel.hpp"
