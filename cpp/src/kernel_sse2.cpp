// The kernel for sse2; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::sse2
#define PRINCIPLED_BRDF_ARCH_NS sse2
#include "kernel.hpp"
