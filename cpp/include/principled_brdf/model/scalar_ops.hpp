// The model's operations on double (docs/model.md), for the float64
// instantiation: exact where the kernels' float32 versions approximate
// (reciprocals, square roots, sin and cos of 2πu, e^x - 1, log), each
// rounded as IEEE double.
// Included inside the namespace that includes the model for double, before it.
#pragma once  // once per translation unit: f64.hpp includes it, in principled_brdf::f64

// a b + c rounded twice: std::fma is a slow library call without FMA
// instructions, and the float64 path needs no single rounding
inline double mul_add(double a, double b, double c) { return a * b + c; }
inline double mul_sub(double a, double b, double c) { return a * b - c; }
inline double neg_mul_add(double a, double b, double c) { return c - a * b; }
inline double reciprocal(double x) { return 1.0 / x; }
inline double reciprocal_sqrt(double x) { return 1.0 / std::sqrt(x); }
inline double square_root(double x) { return std::sqrt(std::max(x, 0.0)); }
inline double square_root_nonnegative(double x) { return std::sqrt(x); }
inline double select(bool mask, double a, double b) { return mask ? a : b; }
// as x86's minps and maxps: the second operand where either is NaN
inline double min(double a, double b) { return a < b ? a : b; }
inline double max(double a, double b) { return a > b ? a : b; }
inline bool any(bool mask) { return mask; }
inline bool all(bool mask) { return mask; }
inline double log(double x) { return std::log(x); }
inline double exp(double x) { return std::exp(x); }
inline double exp_minus_one(double x) { return std::expm1(x); }
// only the double instantiation's: parts of the model no kernel uses (Beckmann's Λ
// and draw, the general GTR family)
inline double log_one_plus(double x) { return std::log1p(x); }
inline double pow(double x, double y) { return std::pow(x, y); }
inline double erfc(double x) { return std::erfc(x); }

// (sin 2πu, cos 2πu)
inline std::pair<double, double> sincos_turns(double u) {
    const double phi = 6.283185307179586476925 * u;
    return {std::sin(phi), std::cos(phi)};
}

// table lookups (model/energy.hpp): the integer part of x >= 0, back to a real
inline int truncate_to_index(double x) { return static_cast<int>(x); }
inline double index_to_real(int i) { return static_cast<double>(i); }
inline int min(int a, int b) { return a < b ? a : b; }
// table lookups of whole nodes (model/dielectric_energy.hpp): floor(x) for x >= 0, and
// (table[i], table[i + 1]) for a whole i held as a real
inline double floor_of(double x) { return std::floor(x); }
inline std::pair<double, double> table_pair(const float* table, double index) {
    const int i = static_cast<int>(index);
    return {static_cast<double>(table[i]), static_cast<double>(table[i + 1])};
}
// the interval of ν = μ + 1/8 (the exact sum: one ulp lower where it rounded up),
// 16 an octave from 1/8, and its end: ν's exponent and top four mantissa bits,
// plus one; ν clamped to [1/8, 9/8] first (NaN to 1/8)
inline std::pair<int, double> energy_interval(double mu) {
    constexpr int shift = 52 - 4;
    auto bits_of = [](double x) {
        std::uint64_t bits;
        std::memcpy(&bits, &x, sizeof bits);
        return bits;
    };
    const double first = energy::kCosineOffset, last = first + 1.0;
    const double nearest = mu + first;
    const double nu = nearest - mu > first ? std::nextafter(nearest, 0.0) : nearest;
    const double clamped = nu > first ? (nu < last ? nu : last) : first;
    const std::uint64_t bits = bits_of(clamped), end_bits = (bits & ~((std::uint64_t(1) << shift) - 1)) + (std::uint64_t(1) << shift);
    double end;
    std::memcpy(&end, &end_bits, sizeof end);
    return {static_cast<int>((bits >> shift) - (bits_of(first) >> shift)), end};
}
// an interval's (value, slope) from a row of them
inline std::pair<double, double> value_and_slope_in_row(const float* row, int interval) {
    return {static_cast<double>(row[2 * interval]), static_cast<double>(row[2 * interval + 1])};
}
template <int intervals>
inline std::pair<double, double> gather_pair_in_row(const float* row, int i) {
    return {static_cast<double>(row[i]), static_cast<double>(row[i + 1])};
}
// an interval's value and slope in two adjacent rows of a corner table (energy_corners.hpp)
inline std::array<double, 4> gather_corners(const float* corners, int row_offset, int interval) {
    const float* c = corners + energy::kCorners * (row_offset + interval);
    return {c[0], c[1], c[2], c[3]};
}
