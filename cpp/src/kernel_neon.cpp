// The kernel for neon; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::neon64
#define PRINCIPLED_BRDF_ARCH_NS neon
#include "kernel.hpp"
