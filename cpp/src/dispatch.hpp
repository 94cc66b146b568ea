// Which kernels this build has and this CPU runs; the one chosen once.
#pragma once

#include <string>
#include <vector>

#include "kernel_api.hpp"

namespace principled_brdf::kernel {

// Compiled in and supported by this CPU, best last.
const std::vector<const KernelTable*>& available();
// The best available, or the one PRINCIPLED_BRDF_ISA names (throws
// std::invalid_argument if that one is not available).
const KernelTable& active();
// An available one by name; throws std::invalid_argument naming `what`.
const KernelTable& by_name(const std::string& isa, const char* what);

}  // namespace principled_brdf::kernel
