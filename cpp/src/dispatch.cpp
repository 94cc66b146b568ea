// CPU detection (cpuid + xgetbv: the OS must have enabled the register state,
// which xsimd 8.1's own detection does not check) and the choice of kernels.
#include "dispatch.hpp"

#include <cstdlib>
#include <stdexcept>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#endif

namespace principled_brdf::kernel {
namespace {

struct CpuFeatures {
    bool sse2 = false;
    bool avx2_fma = false;
    bool avx512 = false;  // F, CD, DQ, BW: what xsimd's avx512bw kernels use
    bool neon = false;
};

#if defined(__x86_64__) || defined(__i386__)
unsigned long long read_xcr0() {
    unsigned eax, edx;
    __asm__ volatile("xgetbv" : "=a"(eax), "=d"(edx) : "c"(0));
    return (static_cast<unsigned long long>(edx) << 32) | eax;
}

CpuFeatures detect() {
    CpuFeatures f;
    unsigned eax, ebx, ecx, edx;
    if (!__get_cpuid(1, &eax, &ebx, &ecx, &edx)) return f;
    f.sse2 = (edx >> 26) & 1;
    const bool fma = (ecx >> 12) & 1;
    const bool osxsave = (ecx >> 27) & 1;
    const bool avx = (ecx >> 28) & 1;
    if (!(osxsave && avx)) return f;
    const unsigned long long xcr0 = read_xcr0();
    const bool os_ymm = (xcr0 & 0x6) == 0x6;           // SSE and AVX state
    const bool os_zmm = (xcr0 & 0xE6) == 0xE6;         // plus opmask, ZMM_Hi256, Hi16_ZMM
    if (!__get_cpuid_count(7, 0, &eax, &ebx, &ecx, &edx)) return f;
    const bool avx2 = (ebx >> 5) & 1;
    const bool avx512f = (ebx >> 16) & 1, avx512dq = (ebx >> 17) & 1;
    const bool avx512cd = (ebx >> 28) & 1, avx512bw = (ebx >> 30) & 1;
    f.avx2_fma = os_ymm && avx2 && fma;
    f.avx512 = f.avx2_fma && os_zmm && avx512f && avx512dq && avx512cd && avx512bw;
    return f;
}
#elif defined(__aarch64__)
CpuFeatures detect() {
    CpuFeatures f;
    f.neon = true;  // Advanced SIMD is mandatory on AArch64
    return f;
}
#else
CpuFeatures detect() { return {}; }
#endif

// Compiled and supported, in increasing order of preference.
std::vector<const KernelTable*> find_available() {
    const CpuFeatures cpu = detect();
    std::vector<const KernelTable*> tables;
#if defined(PRINCIPLED_BRDF_HAVE_SSE2)
    if (cpu.sse2) tables.push_back(&sse2_kernels());
#endif
#if defined(PRINCIPLED_BRDF_HAVE_AVX2)
    if (cpu.avx2_fma) tables.push_back(&avx2_kernels());
#endif
#if defined(PRINCIPLED_BRDF_HAVE_AVX512)
    if (cpu.avx512) tables.push_back(&avx512_kernels());
#endif
#if defined(PRINCIPLED_BRDF_HAVE_NEON)
    if (cpu.neon) tables.push_back(&neon_kernels());
#endif
    (void)cpu;
    return tables;
}

const KernelTable* choose_active() {
    const auto& tables = available();
    if (tables.empty()) throw std::runtime_error("principled_brdf: no SIMD kernel of this build runs on this CPU");
    const char* forced = std::getenv("PRINCIPLED_BRDF_ISA");
    if (forced == nullptr || *forced == '\0') return tables.back();
    return &by_name(forced, "PRINCIPLED_BRDF_ISA");
}

}  // namespace

const std::vector<const KernelTable*>& available() {
    static const std::vector<const KernelTable*> tables = find_available();
    return tables;
}

const KernelTable& by_name(const std::string& isa, const char* what) {
    std::string names;
    for (const KernelTable* table : available()) {
        if (isa == table->isa) return *table;
        names += names.empty() ? "" : ", ";
        names += table->isa;
    }
    throw std::invalid_argument(std::string(what) + ": instruction set '" + isa +
                                "' is not compiled in or not supported by this CPU (available: " + names + ")");
}

const KernelTable& active() {
    static const KernelTable* table = choose_active();
    return *table;
}

}  // namespace principled_brdf::kernel
