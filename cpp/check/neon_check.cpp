// The NEON kernel (kernel_neon.cpp) held to the float64 reference on the same
// float32 inputs with docs/validation.md's bounds: every model (the BRDFs with
// and without the energy compensation, the 2015 solid in both transport modes,
// the thin sheet), every output (f, the lobes, the pdf, f with the pdf, samples,
// the Jacobian in the parameters and the derivatives in the directions),
// per-element and uniform materials, the directions as tests/conftest.py draws
// them or over the whole sphere; and the kernel's own bits (layouts, parts of a
// call, uniform materials, the generator). Built for aarch64 and run under
// emulation by scripts/check-neon.sh; it calls the batch layer (batch.hpp) as
// the Python bindings do. Prints a line per check and exits non-zero on any
// failure, after the line "N passed, M failed".
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "principled_brdf/batch.hpp"
#include "principled_brdf/reference.hpp"
#include "principled_brdf/reference_directions.hpp"

namespace {

using namespace principled_brdf;
namespace ref = principled_brdf::reference;
using Eigen::Vector3d;

const char* const kIsa = "neon";
constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------- random numbers (splitmix64, a fixed seed)

class Random {
public:
    explicit Random(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    bool chance(double p) { return uniform() < p; }
    double normal() { return std::sqrt(-2.0 * std::log1p(-uniform())) * std::cos(2.0 * kPi * uniform()); }

private:
    std::uint64_t state_;
};

// ---------------------------------------------------------------- the models and their options

struct Variant {
    const char* name;
    Model model;
    TransportMode mode = TransportMode::kRadiance;
    bool compensated = false;  // the multiple-scattering energy compensation (the BRDFs only)

    bool bsdf() const { return is_bsdf(model); }
    bool solid() const { return model == Model::kDisney2015; }
    bool has_gradients() const { return !compensated; }
};

const std::array<Variant, 7> kVariants{{
        {"disney2014", Model::kDisney2014},
        {"disney2012", Model::kDisney2012},
        {"disney2014+compensation", Model::kDisney2014, TransportMode::kRadiance, true},
        {"disney2012+compensation", Model::kDisney2012, TransportMode::kRadiance, true},
        {"disney2015", Model::kDisney2015},
        {"disney2015/importance", Model::kDisney2015, TransportMode::kImportance},
        {"disney2015_thin", Model::kDisney2015Thin},
}};

// ---------------------------------------------------------------- inputs

using Row = std::array<float, kParamSlots>;

Row default_row() {
    Row row{};
    for (int s = 0; s < kParamSlots; ++s) row[s] = static_cast<float>(default_of(static_cast<Param>(s)));
    return row;
}

// One call's inputs: n pairs, u for sampling, and a uniform material or one per element.
struct Batch {
    std::string material;  // the uniform material's name, or "per_element"
    int n = 0;
    std::vector<float> wi, wo, u;  // (n, 3) interleaved
    bool uniform = true;
    Row row{};                 // the uniform material
    std::vector<Row> rows;     // per element
    // the kernels' per-element arrays, as the bindings pass them: base_color
    // (n, 3), each other parameter (n,); the slots a model does not read stay uniform
    std::vector<float> base_color;
    std::array<std::vector<float>, kParamSlots> scalars;
    std::array<bool, kParamSlots> per_element_slot{};
    // the reference's rows (the same float32 values)
    std::vector<std::array<double, kParamSlots>> reference_rows;

    const double* reference_row(int i) const { return reference_rows[uniform ? 0 : i].data(); }
};

Vector3d at(const std::vector<float>& a, int i) { return {a[3 * i], a[3 * i + 1], a[3 * i + 2]}; }

void put(std::vector<float>& a, const Vector3d& w) {
    for (int k = 0; k < 3; ++k) a.push_back(static_cast<float>(w[k]));
}

Vector3d from_cos(Random& r, double cos_theta) {
    const double phi = 2.0 * kPi * r.uniform();
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

// Where the directions lie: over the whole sphere (the BSDFs), or above the
// surface with tests/conftest.py's two regimes: cos θ >= 1e-4 with half of
// them near the horizon, or cos θ >= 0.05 (tests/model/test_simd_accuracy_vs_float64.py).
enum class Directions { kSphere, kGrazing, kAwayFromHorizon };

double lowest_cos(Directions d) { return d == Directions::kAwayFromHorizon ? 0.05 : 1e-4; }

// tests/conftest.py's random_directions: 1 % of them the normal
Vector3d hemisphere_direction(Random& r, Directions d) {
    const double lowest = lowest_cos(d);
    double cos_theta = d == Directions::kGrazing && r.chance(0.5) ? std::exp(r.uniform(std::log(lowest), std::log(0.05)))
                                                                  : r.uniform(lowest, 1.0);
    if (r.chance(0.01)) cos_theta = 1.0;
    return from_cos(r, cos_theta);
}

Vector3d sphere_direction(Random& r) {
    Vector3d w(r.normal(), r.normal(), r.normal());
    return w.normalized();
}

Vector3d mirror(const Vector3d& w) { return {-w.x(), -w.y(), w.z()}; }

// w moved into the tangent plane (where f is 0)
Vector3d on_horizon(const Vector3d& w) {
    const Vector3d flat(w.x(), w.y(), 0.0);
    return flat.norm() > 0 ? Vector3d(flat.normalized()) : Vector3d(1.0, 0.0, 0.0);
}

// w moved to within 10^-6 to 10^-44 of the tangent plane on its side (float32's
// subnormal cosines at the far end): divisions by cos θ and its square there
// take tiny and subnormal divisors
Vector3d at_the_last_floats(Random& r, const Vector3d& w) {
    const double cos_theta = std::copysign(std::pow(10.0, r.uniform(-44.0, -6.0)), w.z());
    return std::sqrt(1.0 - cos_theta * cos_theta) * on_horizon(w) + Vector3d(0.0, 0.0, cos_theta);
}

// w moved by a normal step of `sigma` per component, then (above the surface)
// mirrored up and its cos θ raised to the regime's lowest (tests/conftest.py's clamp_cos_theta)
Vector3d near(Random& r, const Vector3d& w, double sigma, Directions d) {
    Vector3d moved = (w + sigma * Vector3d(r.normal(), r.normal(), r.normal())).normalized();
    if (d == Directions::kSphere) return moved;
    moved.z() = std::abs(moved.z());
    const double lowest = lowest_cos(d);
    if (moved.z() >= lowest) return moved;
    return std::sqrt(1.0 - lowest * lowest) * on_horizon(moved) + Vector3d(0.0, 0.0, lowest);
}

// tests/conftest.py's random_direction_pairs: independent pairs and the lobes'
// peaks (the mirror direction, wi = wo and near them); over the sphere also
// straight through (wo = -wi); above the surface one direction in ten mirrored
// below it (where a BRDF is 0); one in a hundred in the tangent plane, and
// (but at cos θ >= 0.05) one in a hundred at the last floats before it.
std::pair<Vector3d, Vector3d> direction_pair(Random& r, Directions d) {
    const bool sphere = d == Directions::kSphere;
    Vector3d wi = sphere ? sphere_direction(r) : hemisphere_direction(r, d);
    Vector3d wo = sphere ? sphere_direction(r) : hemisphere_direction(r, d);
    const double kind = r.uniform();
    if (kind >= 0.60 && kind < 0.70) wo = near(r, mirror(wi), 0.02, d);
    if (kind >= 0.70 && kind < 0.78) wo = mirror(wi);
    if (kind >= 0.78 && kind < 0.86) wo = wi;
    if (kind >= 0.86 && kind < 0.92) wo = near(r, wi, 1e-4, d);
    if (kind >= 0.92) wo = sphere ? Vector3d(-wi) : near(r, wi, 0.3, d);
    if (!sphere && r.chance(0.1)) wi.z() = -wi.z();
    if (!sphere && r.chance(0.1)) wo.z() = -wo.z();
    if (r.chance(0.01)) wi = on_horizon(wi);
    if (r.chance(0.01)) wo = on_horizon(wo);
    if (d != Directions::kAwayFromHorizon && r.chance(0.01)) wi = at_the_last_floats(r, wi);
    if (d != Directions::kAwayFromHorizon && r.chance(0.01)) wo = at_the_last_floats(r, wo);
    return {wi, wo};
}

float scalar(Random& r, double lo, double hi, std::initializer_list<double> edges) {
    if (r.chance(0.2)) {
        const std::vector<double> values(edges);
        return static_cast<float>(values[r.next() % values.size()]);
    }
    return static_cast<float>(r.uniform(lo, hi));
}

// tests/conftest.py's random_material_arrays: the 2012 and 2014 domains with their edges
Row random_brdf_material(Random& r) {
    Row row = default_row();
    for (int c = 0; c < 3; ++c) row[kBaseColorR + c] = static_cast<float>(r.uniform());
    const double edge = r.uniform();
    const int channel = static_cast<int>(r.next() % 3);
    for (int c = 0; c < 3; ++c) {
        float& v = row[kBaseColorR + c];
        if (edge < 0.05) v = 0.0f;                      // black
        else if (edge < 0.10) v = 1.0f;                 // white
        else if (edge < 0.15) v = c == channel ? v : 0.0f;  // saturated
        else if (edge < 0.20) v *= 3.0f;                // brighter than 1
    }
    row[kMetallic] = scalar(r, 0, 1, {0.0, 1.0});
    row[kSubsurface] = scalar(r, 0, 1, {0.0, 1.0});
    row[kSpecular] = scalar(r, 0, 2, {0.0, 1.0, 2.0});
    row[kSpecularTint] = scalar(r, 0, 1, {0.0, 1.0});
    row[kRoughness] = scalar(r, 0, 1, {0.0, 1.0, 0.001, 0.03, 1.5});
    row[kAnisotropic] = scalar(r, 0, 1, {0.0, 1.0});
    row[kSheen] = scalar(r, 0, 2, {0.0, 1.0, 2.0});
    row[kSheenTint] = scalar(r, 0, 1, {0.0, 1.0});
    row[kClearcoat] = scalar(r, 0, 2, {0.0, 1.0, 2.0});
    row[kClearcoatGloss] = scalar(r, 0, 1, {0.0, 1.0});
    return row;
}

// tests/model/test_bsdf2015.py's random_2015_material (and test_bsdf2015_thin.py's diff_trans)
Row random_bsdf_material(Random& r, bool thin) {
    Row row = default_row();
    const bool black = r.chance(0.05);
    for (int c = 0; c < 3; ++c) row[kBaseColorR + c] = black ? 0.0f : static_cast<float>(r.uniform());
    row[kMetallic] = scalar(r, 0, 1, {0.0, 1.0});
    row[kSpecular] = scalar(r, 0, 3, {0.0, 0.5, 2.0});
    row[kSpecularTint] = scalar(r, 0, 1, {0.0, 1.0});
    row[kRoughness] = scalar(r, 0.02, 1, {0.05, 1.0});
    row[kAnisotropic] = scalar(r, 0, 1, {0.0, 1.0});
    row[kSheen] = scalar(r, 0, 1, {0.0, 1.0});
    row[kSheenTint] = scalar(r, 0, 1, {0.0, 1.0});
    row[kClearcoat] = scalar(r, 0, 1, {0.0, 1.0});
    row[kClearcoatGloss] = scalar(r, 0, 1, {0.0, 1.0});
    row[kSpecTrans] = scalar(r, 0, 1, {0.0, 1.0});
    row[kFlatness] = scalar(r, 0, 1, {0.0, 1.0});
    if (thin) row[kDiffTrans] = scalar(r, 0, 2, {0.0, 1.0, 2.0});
    return row;
}

struct NamedMaterial {
    const char* name;
    std::vector<std::pair<Param, float>> values;  // the rest at their defaults
};

// Uniform materials taking each of the kernels' lobe sets (kernel_eval.hpp):
// the metal (specular only), the plain dielectric, and everything.
std::vector<NamedMaterial> uniform_materials(const Variant& v) {
    if (!v.bsdf())
        return {{"default", {}},
                {"gold", {{kBaseColorR, 1.0f}, {kBaseColorG, 0.71f}, {kBaseColorB, 0.29f}, {kMetallic, 1.0f}, {kRoughness, 0.3f}}},
                {"plastic", {{kBaseColorR, 0.9f}, {kBaseColorG, 0.9f}, {kBaseColorB, 0.9f}, {kClearcoat, 1.0f}, {kSheen, 0.5f},
                             {kSubsurface, 0.3f}, {kAnisotropic, 0.5f}}}};
    std::vector<NamedMaterial> materials{
            {"glass", {{kBaseColorR, 0.9f}, {kBaseColorG, 0.95f}, {kBaseColorB, 1.0f}, {kSpecTrans, 1.0f}, {kRoughness, 0.2f}}},
            {"frosted", {{kSpecTrans, 0.6f}, {kRoughness, 0.5f}, {kMetallic, 0.1f}, {kSpecular, 1.2f}, {kAnisotropic, 0.4f},
                         {kFlatness, 0.3f}, {kSheen, 0.3f}, {kClearcoat, 0.5f}}},
            {"opaque", {{kClearcoat, 1.0f}, {kRoughness, 0.4f}, {kSheen, 0.2f}}}};
    if (v.model == Model::kDisney2015Thin)
        materials.push_back({"leaf", {{kBaseColorR, 0.25f}, {kBaseColorG, 0.55f}, {kBaseColorB, 0.1f}, {kRoughness, 0.5f},
                                      {kDiffTrans, 1.2f}, {kSheen, 0.3f}, {kSpecTrans, 0.2f}, {kFlatness, 0.5f}}});
    return materials;
}

// The slots a model reads (params.hpp; the Python side keeps the others at their defaults).
bool reads(const Variant& v, int slot) {
    if (!v.bsdf()) return slot < kGradientSlots;
    if (slot == kSubsurface) return false;
    return slot != kDiffTrans || v.model == Model::kDisney2015Thin;
}

void add_pairs(Batch& b, Random& r, Directions d, int n) {
    b.n = n;
    for (int i = 0; i < n; ++i) {
        const auto [wi, wo] = direction_pair(r, d);
        put(b.wi, wi);
        put(b.wo, wo);
        for (int k = 0; k < 3; ++k) b.u.push_back(static_cast<float>(r.uniform()));
    }
}

// The per-element arrays and the reference's rows of a batch whose material is set.
void finish(Batch& b, const Variant& v) {
    auto as_double = [](const Row& row) {
        std::array<double, kParamSlots> out{};
        std::copy(row.begin(), row.end(), out.begin());
        return out;
    };
    if (b.uniform) {
        b.reference_rows = {as_double(b.row)};
        return;
    }
    b.row = default_row();  // the slots the model does not read
    for (int s = 0; s < kParamSlots; ++s) b.per_element_slot[s] = reads(v, s);
    for (const Row& row : b.rows) {
        b.reference_rows.push_back(as_double(row));
        for (int c = 0; c < 3; ++c) b.base_color.push_back(row[kBaseColorR + c]);
        for (int s = 3; s < kParamSlots; ++s) b.scalars[s].push_back(row[s]);
    }
}

Batch per_element_batch(const Variant& v, Directions d, std::uint64_t seed, int n) {
    Random r(seed);
    Batch b;
    b.material = "per_element";
    add_pairs(b, r, d, n);
    b.uniform = false;
    for (int i = 0; i < n; ++i) b.rows.push_back(v.bsdf() ? random_bsdf_material(r, v.model == Model::kDisney2015Thin)
                                                           : random_brdf_material(r));
    finish(b, v);
    return b;
}

Batch uniform_batch(const Variant& v, Directions d, const NamedMaterial& m, std::uint64_t seed, int n) {
    Random r(seed);
    Batch b;
    b.material = m.name;
    add_pairs(b, r, d, n);
    b.row = default_row();
    for (const auto& [slot, value] : m.values) b.row[slot] = value;
    finish(b, v);
    return b;
}

// The same material given per element (every slot the model reads).
Batch expanded(const Batch& uniform, const Variant& v) {
    Batch b = uniform;
    b.uniform = false;
    b.rows.assign(uniform.n, uniform.row);
    b.reference_rows.clear();
    finish(b, v);
    return b;
}

// ---------------------------------------------------------------- the kernels, through the batch layer

void fill_params(const Batch& b, ParamSlot* params) {
    for (int s = 0; s < kParamSlots; ++s) {
        params[s] = ParamSlot{b.row[s], nullptr, 1};
        if (!b.per_element_slot[s]) continue;
        params[s] = s < 3 ? ParamSlot{0.0f, b.base_color.data() + s, 3} : ParamSlot{0.0f, b.scalars[s].data(), 1};
    }
}

Vec3Array input(const std::vector<float>& a) { return {a.data(), Vec3Layout::kInterleaved, 0}; }
MutableVec3Array output(std::vector<float>& a) { return {a.data(), Vec3Layout::kInterleaved, 0}; }

EvalJob eval_job(const Batch& b, const Variant& v, Output what) {
    EvalJob job;
    job.wi = input(b.wi);
    job.wo = input(b.wo);
    fill_params(b, job.params);
    job.model = v.model;
    job.mode = v.mode;
    job.energy_compensation = v.compensated;
    job.output = what;
    if (v.bsdf()) {  // the 2015 models' derivatives take every slot
        std::array<int, kParamSlots> all{};
        for (int s = 0; s < kParamSlots; ++s) all[s] = s;
        job.columns = Columns(all.data(), kParamSlots);
    }
    return job;
}

void run(const EvalJob& job, int n) {
    if (eval(job, n, 1, kIsa) != -1) throw std::runtime_error("eval reported a bad direction");
}

struct Evaluated {
    std::vector<float> f;          // (n, 3)
    std::vector<float> pdf;        // (n,)
    std::vector<float> jacobian;   // (n, 3, P)
    std::array<std::vector<float>, kLobeCount> lobes;
};

Evaluated kernel_eval(const Batch& b, const Variant& v, Output what, bool cosine = false,
                      SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    EvalJob job = eval_job(b, v, what);
    job.cosine = cosine;
    job.sampler = sampler;
    Evaluated e;
    e.f.assign(3 * b.n, -1.0f);
    job.out[0] = output(e.f);
    if (what == Output::kLobes)
        for (int k = 0; k < kLobeCount; ++k) {
            e.lobes[k].assign(3 * b.n, -1.0f);
            job.out[k] = output(e.lobes[k]);
        }
    if (what == Output::kPdf || what == Output::kValuePdf) {
        e.pdf.assign(b.n, -1.0f);
        job.pdf = e.pdf.data();
    }
    if (what == Output::kGradient || what == Output::kDirectionGradient) {
        e.jacobian.assign(static_cast<std::size_t>(b.n) * job.jacobian_width(), -1.0f);
        job.jacobian = e.jacobian.data();
    }
    run(job, b.n);
    return e;
}

struct Drawn {
    std::vector<float> wi, weight, pdf;
    std::vector<std::int32_t> lobe;
    bool operator==(const Drawn& o) const { return wi == o.wi && weight == o.weight && pdf == o.pdf && lobe == o.lobe; }
};

// Samples with the batch's u, or (with_generator) the counter-based generator of `seed`.
Drawn kernel_sample(const Batch& b, const Variant& v, SpecularSampler sampler, bool with_generator = false,
                    std::uint64_t seed = 0) {
    SampleJob job;
    job.wo = input(b.wo);
    if (!with_generator) job.u = input(b.u);
    job.seed = seed;
    fill_params(b, job.params);
    job.model = v.model;
    job.mode = v.mode;
    job.sampler = sampler;
    job.energy_compensation = v.compensated;
    Drawn d;
    d.wi.assign(3 * b.n, -1.0f);
    d.weight.assign(3 * b.n, -1.0f);
    d.pdf.assign(b.n, -1.0f);
    d.lobe.assign(b.n, -1);
    job.wi = output(d.wi);
    job.weight = output(d.weight);
    job.pdf = d.pdf.data();
    job.lobe = d.lobe.data();
    if (sample(job, b.n, 1, kIsa) != -1) throw std::runtime_error("sample reported a bad direction");
    return d;
}

// ---------------------------------------------------------------- the float64 reference

ref::Lobes lobes_of(const ref::Shading<double>& s, const Vector3d& wi, const Vector3d& wo, const Variant& v) {
    return ref::eval_lobes(s, wi, wo, v.model);
}
ref::Lobes lobes_of(const ref::Compensated& c, const Vector3d& wi, const Vector3d& wo, const Variant& v) {
    return ref::eval_lobes(c, wi, wo, v.model);
}
template <class S, ref::If2015<S> = 0>
ref::Lobes lobes_of(const S& s, const Vector3d& wi, const Vector3d& wo, const Variant& v) {
    return ref::eval_lobes(s, wi, wo, v.mode);
}
Vector3d f_of(const ref::Shading<double>& s, const Vector3d& wi, const Vector3d& wo, const Variant& v) {
    return ref::eval(s, wi, wo, v.model);
}
Vector3d f_of(const ref::Compensated& c, const Vector3d& wi, const Vector3d& wo, const Variant& v) {
    return ref::eval(c, wi, wo, v.model);
}
template <class S, ref::If2015<S> = 0>
Vector3d f_of(const S& s, const Vector3d& wi, const Vector3d& wo, const Variant& v) {
    return ref::eval(s, wi, wo, v.mode);
}
ref::Sample sample_of(const ref::Shading<double>& s, const Vector3d& wo, const Vector3d& u, const Variant& v, SpecularSampler sampler) {
    return ref::sample(s, wo, u[0], u[1], u[2], v.model, sampler);
}
ref::Sample sample_of(const ref::Compensated& c, const Vector3d& wo, const Vector3d& u, const Variant& v, SpecularSampler sampler) {
    return ref::sample(c, wo, u[0], u[1], u[2], v.model, sampler);
}
template <class S, ref::If2015<S> = 0>
ref::Sample sample_of(const S& s, const Vector3d& wo, const Vector3d& u, const Variant& v, SpecularSampler sampler) {
    return ref::sample(s, wo, u[0], u[1], u[2], sampler, v.mode);
}

// The reference's prepared materials of one batch: f(prepared row i) for each
// element i, through the cache of the variant's kind (bind_reference.cpp's choice).
template <class Function>
void each_prepared(const Batch& b, const Variant& v, Function&& f) {
    auto loop = [&](auto& cache) {
        for (int i = 0; i < b.n; ++i) f(i, cache.of(b.reference_row(i)));
    };
    if (v.bsdf()) {
        ref::with_cache2015<ref::Shading2015Cache>(v.model, false, loop);
    } else if (v.compensated && v.model == Model::kDisney2012) {
        ref::CompensatedCache<Model::kDisney2012> cache;
        loop(cache);
    } else if (v.compensated) {
        ref::CompensatedCache<Model::kDisney2014> cache;
        loop(cache);
    } else {
        ref::ShadingCache cache;
        loop(cache);
    }
}

// ∂f_c/∂p, (n, 3, P) with P = gradient_slots(model)
std::vector<double> reference_jacobian(const Batch& b, const Variant& v) {
    const int width = 3 * gradient_slots(v.model);
    std::vector<double> out(static_cast<std::size_t>(b.n) * width);
    auto store = [&](int i, const auto& g) { std::copy(g.jacobian.data(), g.jacobian.data() + width, out.begin() + width * i); };
    auto loop_2015 = [&](auto& cache) {
        for (int i = 0; i < b.n; ++i) store(i, ref::eval_grad(cache.of(b.reference_row(i)), at(b.wi, i), at(b.wo, i), v.mode));
    };
    if (v.bsdf()) {
        ref::with_cache2015<ref::GradientShading2015Cache>(v.model, false, loop_2015);
    } else {
        ref::GradientShadingCache cache;
        for (int i = 0; i < b.n; ++i) store(i, ref::eval_grad(cache.of(b.reference_row(i)), at(b.wi, i), at(b.wo, i), v.model));
    }
    return out;
}

// ∂f_c/∂(wi_x, wi_y, wi_z, wo_x, wo_y, wo_z), (n, 3, 6); f times |cos θl| with cosine
std::vector<double> reference_direction_jacobian(const Batch& b, const Variant& v, bool cosine) {
    constexpr int width = 3 * kDirectionComponents;
    std::vector<double> out(static_cast<std::size_t>(b.n) * width);
    auto store = [&](int i, const ref::DirectionGradient& g) {
        std::copy(g.jacobian.data(), g.jacobian.data() + width, out.begin() + width * i);
    };
    auto loop_2015 = [&](auto& cache) {
        for (int i = 0; i < b.n; ++i)
            store(i, ref::eval_direction_grad(cache.of(b.reference_row(i)), at(b.wi, i), at(b.wo, i), cosine, v.mode));
    };
    if (v.bsdf()) {
        ref::with_cache2015<ref::DirectionShading2015Cache>(v.model, false, loop_2015);
    } else {
        ref::DirectionShadingCache cache;
        for (int i = 0; i < b.n; ++i)
            store(i, ref::eval_direction_grad(cache.of(b.reference_row(i)), at(b.wi, i), at(b.wo, i), v.model, cosine));
    }
    return out;
}

// tests/model/test_bsdf2015.py's transmittance_conditioning: κ = c² / (2 η_t²
// |cos²θt|), the magnification of the float32 rounding of the microfacet
// cosine c = wo·h into the solid's transmittance near the critical angle; 0
// where light does not pass through the solid's interface.
double transmittance_conditioning(const Variant& v, double specular, const Vector3d& wi, const Vector3d& wo) {
    if (!v.solid()) return 0.0;
    const double eta = std::max(2.0 / (1.0 - std::sqrt(0.08 * specular)) - 1.0, 1.001);
    const bool inside = wo.z() < 0;
    const Vector3d side(1.0, 1.0, inside ? -1.0 : 1.0);
    const Vector3d view = wo.cwiseProduct(side), light = wi.cwiseProduct(side);
    if (!(view.z() > 0 && light.z() < 0)) return 0.0;
    const double eta_t = inside ? 1.0 / eta : eta;
    const Vector3d h = view + eta_t * light;
    const double c = std::abs(view.dot(h)) / h.norm();
    const double cos2_t = (c * c + eta_t * eta_t - 1.0) / (eta_t * eta_t);
    return c * c / (2.0 * eta_t * eta_t * std::abs(cos2_t));
}

// The share of the 1e-4 bound that κ takes: errors of the solid's transmission,
// f and pdf (which splits reflection and transmission by F) are divided by it.
double conditioning(const Batch& b, const Variant& v, int i, const Vector3d& wi, const Vector3d& wo) {
    return 1.0 + 1e-2 * transmittance_conditioning(v, b.reference_row(i)[kSpecular], wi, wo);
}

// ---------------------------------------------------------------- errors and bounds

constexpr double kFloor = 1e-6;  // docs/validation.md: relative to max(|reference|, 1e-6)

double relative_error(double simd, double reference) {
    if (!std::isfinite(simd)) return std::numeric_limits<double>::infinity();
    return std::abs(simd - reference) / std::max(std::abs(reference), kFloor);
}

// numpy's percentile (linear interpolation between order statistics)
double percentile(std::vector<double> values, double q) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const double position = q / 100.0 * static_cast<double>(values.size() - 1);
    const std::size_t below = static_cast<std::size_t>(position);
    const std::size_t above = std::min(below + 1, values.size() - 1);
    return values[below] + (position - static_cast<double>(below)) * (values[above] - values[below]);
}

struct Bounds {
    double p9999, max;
};

// docs/validation.md's bounds of f, the lobes, pdfs and sample weights: for
// the BRDFs 5e-6 and 5e-5 with cos θ >= 0.05, 5e-5 and 1e-3 with half of the
// directions near the horizon; for the 2015 models over the sphere 1e-4 and 1e-3.
Bounds value_bounds(Directions d) {
    switch (d) {
        case Directions::kAwayFromHorizon: return {5e-6, 5e-5};
        case Directions::kGrazing: return {5e-5, 1e-3};
        case Directions::kSphere: break;
    }
    return {1e-4, 1e-3};
}
constexpr Bounds kGradientBounds{1e-4, 1e-2};  // the Jacobians, relative to their per-element scale

class Tally {
public:
    // One line: the errors' 99.99th percentile and maximum against the bounds.
    void errors(const std::string& what, const std::vector<double>& errors, Bounds bounds, const std::string& note = "") {
        const double p = percentile(errors, 99.99);
        const double worst = errors.empty() ? 0.0 : *std::max_element(errors.begin(), errors.end());
        const bool ok = !errors.empty() && p <= bounds.p9999 && worst <= bounds.max;
        std::printf("%-4s %-58s p99.99 %8.2e (<= %.0e)  max %8.2e (<= %.0e)  n %zu%s%s\n", ok ? "ok" : "FAIL",
                    what.c_str(), p, bounds.p9999, worst, bounds.max, errors.size(), note.empty() ? "" : "  ", note.c_str());
        count(ok);
    }
    // One line: a fraction of agreeing elements against its lower bound.
    void fraction(const std::string& what, double value, double lowest, const std::string& note = "") {
        const bool ok = value >= lowest;
        std::printf("%-4s %-58s %.5f (>= %g)%s%s\n", ok ? "ok" : "FAIL", what.c_str(), value, lowest,
                    note.empty() ? "" : "  ", note.c_str());
        count(ok);
    }
    // One line: two results that must hold the same bits.
    void same_bits(const std::string& what, bool same) {
        std::printf("%-4s %-58s same bits\n", same ? "ok" : "FAIL", what.c_str());
        count(same);
    }
    int failed() const { return failed_; }
    int passed() const { return passed_; }

private:
    void count(bool ok) { ++(ok ? passed_ : failed_); }
    int passed_ = 0, failed_ = 0;
};

// The errors of one output over a kind's batches, added up batch by batch.
using Errors = std::vector<double>;

std::string label(const Variant& v, const std::string& kind, const std::string& output) {
    return std::string(v.name) + "  " + kind + "  " + output;
}

// ---------------------------------------------------------------- the checks of one output

// f (and, with lobes, every lobe) against the reference; 2015 solid's
// transmission and f conditioned by κ (as a share of the 1e-4 bound).
void value_errors(const Batch& b, const Variant& v, Errors& f_errors, std::array<Errors, kLobeCount>* lobe_errors) {
    const Evaluated simd = kernel_eval(b, v, Output::kTotal);
    Evaluated lobes;
    if (lobe_errors != nullptr) lobes = kernel_eval(b, v, Output::kLobes);
    each_prepared(b, v, [&](int i, const auto& prepared) {
        const Vector3d wi = at(b.wi, i), wo = at(b.wo, i);
        const double kappa = conditioning(b, v, i, wi, wo);
        const ref::Lobes expected = lobes_of(prepared, wi, wo, v);
        const Vector3d f = f_of(prepared, wi, wo, v);
        for (int c = 0; c < 3; ++c) f_errors.push_back(relative_error(simd.f[3 * i + c], f[c]) / kappa);
        if (lobe_errors == nullptr) return;
        const std::array<Vector3d, kLobeCount> parts{expected.diffuse, expected.sheen, expected.specular, expected.clearcoat,
                                                      expected.multiple_scattering, expected.transmission,
                                                      expected.diffuse_transmission};
        for (int k = 0; k < kLobeCount; ++k) {
            const double scale = k == 5 ? kappa : 1.0;  // transmission
            for (int c = 0; c < 3; ++c) (*lobe_errors)[k].push_back(relative_error(lobes.lobes[k][3 * i + c], parts[k][c]) / scale);
        }
    });
}

void pdf_errors(const Batch& b, const Variant& v, SpecularSampler sampler, Errors& errors) {
    const Evaluated simd = kernel_eval(b, v, Output::kPdf, false, sampler);
    each_prepared(b, v, [&](int i, const auto& prepared) {
        const Vector3d wi = at(b.wi, i), wo = at(b.wo, i);
        errors.push_back(relative_error(simd.pdf[i], ref::pdf(prepared, wi, wo, sampler)) / conditioning(b, v, i, wi, wo));
    });
}

// eval_pdf: f |cos θl| and the pdf in one pass
void value_pdf_errors(const Batch& b, const Variant& v, Errors& value_errors, Errors& pdf_errors) {
    const Evaluated simd = kernel_eval(b, v, Output::kValuePdf, true);
    each_prepared(b, v, [&](int i, const auto& prepared) {
        const Vector3d wi = at(b.wi, i), wo = at(b.wo, i);
        const double kappa = conditioning(b, v, i, wi, wo);
        const Vector3d f = f_of(prepared, wi, wo, v) * std::abs(wi.z());
        for (int c = 0; c < 3; ++c) value_errors.push_back(relative_error(simd.f[3 * i + c], f[c]) / kappa);
        pdf_errors.push_back(relative_error(simd.pdf[i], ref::pdf(prepared, wi, wo, SpecularSampler::kVisibleNormals)) / kappa);
    });
}

struct SampleErrors {
    Errors pdf, weight;
    int count = 0, same_lobe = 0, same_lobe_checked = 0, close = 0;
};

// A drawn wi's pdf and weight against the reference's pdf and f |cos θl| / pdf
// at that (float32) wi; the draw against the reference sampler's for the same u.
void sample_errors(const Batch& b, const Variant& v, SpecularSampler sampler, SampleErrors& e) {
    const Drawn simd = kernel_sample(b, v, sampler);
    each_prepared(b, v, [&](int i, const auto& prepared) {
        const Vector3d wi = at(simd.wi, i), wo = at(b.wo, i);
        const bool valid = simd.pdf[i] > 0;
        const double pdf = valid ? ref::pdf(prepared, wi, wo, sampler) : 0.0;
        const Vector3d f_cos = f_of(prepared, wi, wo, v) * std::abs(wi.z());
        const double kappa = conditioning(b, v, i, wi, wo);
        e.pdf.push_back(relative_error(simd.pdf[i], pdf) / kappa);
        for (int c = 0; c < 3; ++c) {
            const double weight = valid && pdf > 0 ? f_cos[c] / pdf : 0.0;
            e.weight.push_back(relative_error(simd.weight[3 * i + c], weight) / kappa);
        }
        const ref::Sample drawn = sample_of(prepared, wo, at(b.u, i), v, sampler);
        ++e.count;
        if (drawn.lobe != simd.lobe[i]) return;
        ++e.same_lobe;
        if (!(drawn.pdf > 1e-3)) return;  // tests/model/test_bsdf2015.py: directions where the pdf is not tiny
        ++e.same_lobe_checked;
        e.close += (wi - drawn.wi).cwiseAbs().maxCoeff() <= 2e-4 && valid;
    });
}

// |g32 - g64| / max(|g64|, 1e-3 max_k |g64_k|, 1e-3 FLT_MIN) of the same element
// and channel, k over the columns (tests/gradients/); `normal` gets those
// whose scale is in float32's normal range.
void jacobian_errors(const std::vector<float>& simd, const std::vector<double>& expected, int n, int columns,
                     Errors& errors, Errors* normal = nullptr, const std::vector<double>* conditioning = nullptr) {
    const double tiny = std::numeric_limits<float>::min();
    for (int i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            const std::size_t first = (3 * static_cast<std::size_t>(i) + c) * columns;
            double largest = 0.0;
            for (int k = 0; k < columns; ++k) largest = std::max(largest, std::abs(expected[first + k]));
            for (int k = 0; k < columns; ++k) {
                const double g64 = expected[first + k], g32 = simd[first + k];
                const double scale = std::max({std::abs(g64), 1e-3 * largest, 1e-3 * tiny});
                const double error = std::isfinite(g32) ? std::abs(g32 - g64) / scale : std::numeric_limits<double>::infinity();
                errors.push_back(conditioning != nullptr ? error / (*conditioning)[i] : error);
                if (normal != nullptr && scale >= tiny) normal->push_back(error);
            }
        }
}

// ---------------------------------------------------------------- one model, one kind of material

struct KindErrors {
    Errors f, f_cos, value_pdf_pdf, pdf_visible, pdf_distribution, gradient, direction, direction_normal;
    std::array<Errors, kLobeCount> lobes;
    SampleErrors sample_visible, sample_distribution;
    bool gradient_f_same = true, direction_f_same = true, value_pdf_same = true;
};

void measure(const Batch& b, const Variant& v, bool direction_cosine, KindErrors& e) {
    value_errors(b, v, e.f, &e.lobes);
    pdf_errors(b, v, SpecularSampler::kVisibleNormals, e.pdf_visible);
    pdf_errors(b, v, SpecularSampler::kDistribution, e.pdf_distribution);
    value_pdf_errors(b, v, e.f_cos, e.value_pdf_pdf);
    sample_errors(b, v, SpecularSampler::kVisibleNormals, e.sample_visible);
    sample_errors(b, v, SpecularSampler::kDistribution, e.sample_distribution);
    // the outputs that also return f or the pdf return eval's and pdf's bits
    const Evaluated f = kernel_eval(b, v, Output::kTotal), f_cos = kernel_eval(b, v, Output::kTotal, direction_cosine);
    const Evaluated with_cos = kernel_eval(b, v, Output::kTotal, true), pdf = kernel_eval(b, v, Output::kPdf);
    const Evaluated value_pdf = kernel_eval(b, v, Output::kValuePdf, true);
    e.value_pdf_same = e.value_pdf_same && value_pdf.f == with_cos.f && value_pdf.pdf == pdf.pdf;
    if (!v.has_gradients()) return;
    const Evaluated gradient = kernel_eval(b, v, Output::kGradient);
    std::vector<double> kappa(b.n);  // the solid's transmittance near the critical angle, as its f's
    for (int i = 0; i < b.n; ++i) kappa[i] = conditioning(b, v, i, at(b.wi, i), at(b.wo, i));
    jacobian_errors(gradient.jacobian, reference_jacobian(b, v), b.n, gradient_slots(v.model), e.gradient, nullptr, &kappa);
    e.gradient_f_same = e.gradient_f_same && gradient.f == f.f;
    const Evaluated direction = kernel_eval(b, v, Output::kDirectionGradient, direction_cosine);
    jacobian_errors(direction.jacobian, reference_direction_jacobian(b, v, direction_cosine), b.n, kDirectionComponents,
                    e.direction, &e.direction_normal);
    e.direction_f_same = e.direction_f_same && direction.f == f_cos.f;
}

void report(Tally& tally, const Variant& v, const std::string& kind, Directions d, const KindErrors& e,
            bool direction_cosine) {
    const Bounds bounds = value_bounds(d);
    tally.errors(label(v, kind, "eval"), e.f, bounds);
    for (int k = 0; k < kLobeCount; ++k)
        tally.errors(label(v, kind, std::string("eval_lobes.") + kLobeNames[k]), e.lobes[k], bounds);
    tally.errors(label(v, kind, "pdf (visible)"), e.pdf_visible, bounds);
    tally.errors(label(v, kind, "pdf (distribution)"), e.pdf_distribution, bounds);
    tally.errors(label(v, kind, "eval_pdf value (cosine)"), e.f_cos, bounds);
    tally.errors(label(v, kind, "eval_pdf pdf"), e.value_pdf_pdf, bounds);
    tally.same_bits(label(v, kind, "eval_pdf == (eval, pdf)"), e.value_pdf_same);
    for (const auto& [name, s] : {std::pair<const char*, const SampleErrors*>{"visible", &e.sample_visible},
                                  {"distribution", &e.sample_distribution}}) {
        const std::string sampler = std::string(" (") + name + ")";
        tally.errors(label(v, kind, "sample pdf at wi" + sampler), s->pdf, bounds);
        tally.errors(label(v, kind, "sample weight at wi" + sampler), s->weight, bounds);
        tally.fraction(label(v, kind, "sample lobe as reference's" + sampler), double(s->same_lobe) / s->count, 0.999);
        tally.fraction(label(v, kind, "sample wi within 2e-4 of reference's" + sampler),
                       s->same_lobe_checked ? double(s->close) / s->same_lobe_checked : 0.0, 0.999, "(its lobe, pdf > 1e-3)");
    }
    if (!v.has_gradients()) return;
    tally.errors(label(v, kind, "eval_grad"), e.gradient, kGradientBounds);
    tally.same_bits(label(v, kind, "eval_grad f == eval"), e.gradient_f_same);
    const std::string cosine = direction_cosine ? " (cosine)" : "";
    tally.errors(label(v, kind, "direction grad" + cosine), e.direction, kGradientBounds);
    // tests/gradients/: in float32's normal range each entry is the double sum rounded once
    tally.errors(label(v, kind, "direction grad" + cosine + ", normal range"), e.direction_normal, Bounds{1e-7, 1e-7});
    tally.same_bits(label(v, kind, "direction grad f == eval" + cosine), e.direction_f_same);
}

// ---------------------------------------------------------------- the kernels' own bits

template <class T>
std::vector<T> slice(const std::vector<T>& a, int first, int count, int width) {
    return {a.begin() + static_cast<std::ptrdiff_t>(width) * first, a.begin() + static_cast<std::ptrdiff_t>(width) * (first + count)};
}

// A part of a call (another start and length: the tail, the pipelined loop's
// prologue) gives the whole call's bits for its elements.
Batch part_of(const Batch& b, int first, int count) {
    Batch p = b;
    p.n = count;
    p.wi = slice(b.wi, first, count, 3);
    p.wo = slice(b.wo, first, count, 3);
    p.u = slice(b.u, first, count, 3);
    if (!b.uniform) {
        p.rows = slice(b.rows, first, count, 1);
        p.base_color = slice(b.base_color, first, count, 3);
        for (int s = 3; s < kParamSlots; ++s)
            if (!b.scalars[s].empty()) p.scalars[s] = slice(b.scalars[s], first, count, 1);
        p.reference_rows = slice(b.reference_rows, first, count, 1);
    }
    return p;
}

bool same_drawn_part(const Drawn& whole, const Drawn& part, int first, int count) {
    return slice(whole.wi, first, count, 3) == part.wi && slice(whole.weight, first, count, 3) == part.weight &&
           slice(whole.pdf, first, count, 1) == part.pdf && slice(whole.lobe, first, count, 1) == part.lobe;
}

void check_bits(Tally& tally, const Variant& v, const std::string& kind, const std::vector<Batch>& batches) {
    bool layouts = true, parts = true, generator = true, uniform_as_per_element = true;
    for (const Batch& b : batches) {
        const Evaluated whole = kernel_eval(b, v, Output::kTotal);
        // the (3, N) layout in and out
        std::vector<float> wi_rows(3 * b.n), wo_rows(3 * b.n), f_rows(3 * b.n);
        for (int i = 0; i < b.n; ++i)
            for (int k = 0; k < 3; ++k) {
                wi_rows[k * b.n + i] = b.wi[3 * i + k];
                wo_rows[k * b.n + i] = b.wo[3 * i + k];
            }
        EvalJob job = eval_job(b, v, Output::kTotal);
        job.wi = {wi_rows.data(), Vec3Layout::kRows, b.n};
        job.wo = {wo_rows.data(), Vec3Layout::kRows, b.n};
        job.out[0] = {f_rows.data(), Vec3Layout::kRows, b.n};
        run(job, b.n);
        for (int i = 0; i < b.n; ++i)
            for (int k = 0; k < 3; ++k) layouts = layouts && f_rows[k * b.n + i] == whole.f[3 * i + k];
        // parts of the call
        const Drawn drawn = kernel_sample(b, v, SpecularSampler::kVisibleNormals);
        for (const auto& [first, count] : {std::pair<int, int>{0, 1}, {3, 5}, {5, 77}, {16, 143}, {b.n - 97, 97}}) {
            const Batch p = part_of(b, first, count);
            parts = parts && kernel_eval(p, v, Output::kTotal).f == slice(whole.f, first, count, 3);
            parts = parts && same_drawn_part(drawn, kernel_sample(p, v, SpecularSampler::kVisibleNormals), first, count);
        }
        // the counter-based generator (batch.hpp's counter_uniforms, scalar) as the kernels draw it
        Batch given = b;
        counter_uniforms(2024, 0, b.n, given.u.data());
        generator = generator && kernel_sample(b, v, SpecularSampler::kVisibleNormals, true, 2024) ==
                                         kernel_sample(given, v, SpecularSampler::kVisibleNormals);
        if (!b.uniform || v.compensated) continue;
        // a uniform material runs its own loops (hoisted, pipelined, its lobe set's)
        const Batch each = expanded(b, v);
        uniform_as_per_element = uniform_as_per_element && kernel_eval(each, v, Output::kTotal).f == whole.f &&
                                 kernel_eval(each, v, Output::kPdf).pdf == kernel_eval(b, v, Output::kPdf).pdf &&
                                 kernel_sample(each, v, SpecularSampler::kVisibleNormals) == drawn;
        if (v.has_gradients())
            uniform_as_per_element = uniform_as_per_element &&
                                     kernel_eval(each, v, Output::kGradient).jacobian == kernel_eval(b, v, Output::kGradient).jacobian &&
                                     kernel_eval(each, v, Output::kDirectionGradient).jacobian ==
                                             kernel_eval(b, v, Output::kDirectionGradient).jacobian;
    }
    tally.same_bits(label(v, kind, "eval (3, N) layout == (N, 3)"), layouts);
    tally.same_bits(label(v, kind, "eval, sample: parts of a call == the whole"), parts);
    tally.same_bits(label(v, kind, "sample: counter generator == its uniforms given"), generator);
    // (not with the energy compensation: its uniform loop differs from the per-element one on every instruction set)
    if (kind != "per_element" && !v.compensated) tally.same_bits(label(v, kind, "uniform == the same material per element"), uniform_as_per_element);
}

// ---------------------------------------------------------------- main

constexpr int kPerElementPairs = 4003;  // not a multiple of the 4 lanes: the tail
constexpr int kUniformPairs = 1335;     // each uniform material's

// A kind of material with its directions (the BRDFs' per-element materials
// near the horizon too, their uniform ones at cos θ >= 0.05, as tests/ draws them).
struct Kind {
    const char* name;
    Directions directions;
    std::vector<Batch> batches;
    bool direction_cosine;  // the cosine option of the derivatives in the directions on one of the two kinds
};

void check_variant(Tally& tally, const Variant& v, std::uint64_t seed) {
    Kind per_element{"per_element", v.bsdf() ? Directions::kSphere : Directions::kGrazing, {}, false};
    per_element.batches.push_back(per_element_batch(v, per_element.directions, seed, kPerElementPairs));
    Kind uniform{"uniform", v.bsdf() ? Directions::kSphere : Directions::kAwayFromHorizon, {}, true};
    for (const NamedMaterial& m : uniform_materials(v))
        uniform.batches.push_back(uniform_batch(v, uniform.directions, m, ++seed * 7919, kUniformPairs));
    for (const Kind* kind : {&per_element, &uniform}) {
        KindErrors e;
        for (const Batch& b : kind->batches) measure(b, v, kind->direction_cosine, e);
        report(tally, v, kind->name, kind->directions, e, kind->direction_cosine);
        check_bits(tally, v, kind->name, kind->batches);
    }
}

}  // namespace

int main() {
    Tally tally;
    try {
        std::printf("instruction sets: ");
        for (const std::string& isa : available_isas()) std::printf("%s ", isa.c_str());
        std::printf("(active %s, %d float lanes)\n", active_isa().c_str(), float_lanes(kIsa));
        std::printf("errors: |simd - ref| / max(|ref|, 1e-6); a Jacobian's relative to max(|g64|, 1e-3 max_k |g64_k|, 1e-3 FLT_MIN)\n"
                    "of its element and channel; the 2015 solid's f, transmission, pdf and Jacobian divided by 1 + 1e-2 kappa\n"
                    "(kappa: the transmittance's conditioning near the critical angle, tests/model/test_bsdf2015.py)\n");
        std::uint64_t seed = 20261204;
        for (const Variant& v : kVariants) check_variant(tally, v, seed += 1000);
    } catch (const std::exception& error) {
        std::printf("FAIL error: %s\n", error.what());
        std::printf("%d passed, %d failed\n", tally.passed(), tally.failed() + 1);
        return 1;
    }
    std::printf("%d passed, %d failed\n", tally.passed(), tally.failed());
    return tally.failed() == 0 ? 0 : 1;
}
