// Throughput of the batched evaluator (items = direction pairs), with the
// yardsticks of bench/RESULTS.md in the same run: the float64 reference,
// a -O3 -march=native -ffast-math loop of the same math, and a copy kernel
// that moves the same bytes as eval (the memory roofline).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "materials.hpp"
#include "native_loop.hpp"
#include "principled_brdf/batch.hpp"
#include "principled_brdf/reference.hpp"

namespace pb = principled_brdf;

namespace {

constexpr std::int64_t kSizes[] = {4096, 65536, 16 << 20};
constexpr std::int64_t kGradientInCache = 1024;

// Random pairs in the upper hemisphere (or, sphere, over the whole sphere)
// and random per-element materials, in both layouts, made once per size.
struct Data {
    std::int64_t n;
    std::vector<float> wi_aos, wo_aos, wi_soa, wo_soa, out, jacobian;
    std::vector<float> params[pb::kParamSlots];  // per-element, base_color interleaved in slot 0
};

Data& data_for(std::int64_t n, bool sphere = false) {
    static std::map<std::pair<std::int64_t, bool>, std::unique_ptr<Data>> cache;
    auto& slot = cache[{n, sphere}];
    if (slot) return *slot;
    slot = std::make_unique<Data>();
    Data& d = *slot;
    d.n = n;
    std::mt19937_64 rng(1234);
    std::normal_distribution<float> normal;
    std::uniform_real_distribution<float> uniform;
    auto directions = [&](std::vector<float>& aos, std::vector<float>& soa) {
        aos.resize(3 * n);
        soa.resize(3 * n);
        for (std::int64_t i = 0; i < n; ++i) {
            float x = normal(rng), y = normal(rng), z = sphere ? normal(rng) : std::abs(normal(rng)) + 1e-3f;
            const float inv = 1.0f / std::sqrt(x * x + y * y + z * z);
            x *= inv, y *= inv, z *= inv;
            aos[3 * i] = soa[i] = x;
            aos[3 * i + 1] = soa[n + i] = y;
            aos[3 * i + 2] = soa[2 * n + i] = z;
        }
    };
    directions(d.wi_aos, d.wi_soa);
    directions(d.wo_aos, d.wo_soa);
    d.out.resize(12 * n);
    d.jacobian.resize(static_cast<std::size_t>(pb::kJacobianWidth) * n);
    d.params[pb::kBaseColorR].resize(3 * n);
    for (auto& v : d.params[pb::kBaseColorR]) v = uniform(rng);
    for (int s = pb::kMetallic; s < pb::kParamSlots; ++s) {
        d.params[s].resize(n);
        for (auto& v : d.params[s]) v = uniform(rng);
    }
    return d;
}

pb::EvalJob make_job(Data& d, bool soa, bool per_element) {
    pb::EvalJob job;
    const auto layout = soa ? pb::Vec3Layout::kRows : pb::Vec3Layout::kInterleaved;
    const std::int64_t stride = soa ? d.n : 0;
    job.wi = {soa ? d.wi_soa.data() : d.wi_aos.data(), layout, stride};
    job.wo = {soa ? d.wo_soa.data() : d.wo_aos.data(), layout, stride};
    job.out[0] = {d.out.data(), layout, stride};
    const float uniform[pb::kParamSlots] = {0.82f, 0.67f, 0.16f, 0.2f, 0.3f, 0.5f, 0.1f, 0.4f, 0.3f, 0.2f, 0.5f, 0.5f, 0.7f};
    for (int s = 0; s < pb::kParamSlots; ++s) job.params[s].value = uniform[s];
    if (per_element) {
        for (int s = 0; s < 3; ++s) job.params[s] = {0.0f, d.params[pb::kBaseColorR].data() + s, 3};
        for (int s = pb::kMetallic; s < pb::kParamSlots; ++s) job.params[s] = {0.0f, d.params[s].data(), 1};
    }
    return job;
}

int threads_of(const benchmark::State& state) {
    return state.range(1) == 0 ? pb::hardware_threads() : static_cast<int>(state.range(1));
}

void simd_eval_with(benchmark::State& state, const std::string& isa, bool soa, bool per_element, bool checked,
                    pb::Output output, bool energy_compensation) {
    Data& d = data_for(state.range(0));
    pb::EvalJob job = make_job(d, soa, per_element);
    if (checked) job.check = pb::direction_check(1e-3);  // what pb.eval does by default
    job.output = output;  // f; with the pdf (pb.eval_pdf); with the Jacobian (pb.eval_grad)
    job.energy_compensation = energy_compensation;  // the multiple-scattering lobe (pb.eval(..., energy_compensation=True))
    std::vector<float> pdf(output == pb::Output::kValuePdf ? d.n : 0);
    job.pdf = pdf.data();
    job.jacobian = d.jacobian.data();
    job.jacobian_row_stride = soa ? d.n : 0;
    const int threads = threads_of(state);
    for (auto _ : state) {
        pb::eval(job, d.n, threads, isa);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * d.n);
}

void simd_eval(benchmark::State& state, std::string isa, bool soa, bool per_element, bool checked, pb::Output output) {
    simd_eval_with(state, isa, soa, per_element, checked, output, false);
}

// f with the multiple-scattering energy compensation (pb.eval(..., energy_compensation=True))
void simd_eval_compensated(benchmark::State& state, std::string isa, bool soa, bool per_element) {
    simd_eval_with(state, isa, soa, per_element, false, pb::Output::kTotal, true);
}

// The material set (materials.hpp): material `index`, or the random
// per-element materials at index -1, with (N, 3) arrays.
pb::EvalJob make_material_job(Data& d, int index) {
    pb::EvalJob job = make_job(d, false, index < 0);
    if (index >= 0)
        for (int s = 0; s < pb::kParamSlots; ++s) job.params[s].value = bench::kMaterials[index].slots[s];
    return job;
}

// f of the material set, the direction check on or off, with or without the energy compensation.
void simd_eval_material(benchmark::State& state, std::string isa, int index, bool checked, bool energy_compensation) {
    Data& d = data_for(state.range(0));
    pb::EvalJob job = make_material_job(d, index);
    if (checked) job.check = pb::direction_check(1e-3);
    job.energy_compensation = energy_compensation;
    const int threads = threads_of(state);
    for (auto _ : state) {
        pb::eval(job, d.n, threads, isa);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * d.n);
}

// Importance sampling with the counter-based generator: wi, pdf, weight, lobe per element.
void simd_sample_job(benchmark::State& state, const std::string& isa, const pb::EvalJob& eval_job,
                     pb::Model model = pb::Model::kDisney2014) {
    Data& d = data_for(state.range(0));
    pb::SampleJob job;
    job.model = model;
    job.energy_compensation = eval_job.energy_compensation;
    job.wo = eval_job.wo;
    job.seed = 7;
    for (int s = 0; s < pb::kParamSlots; ++s) job.params[s] = eval_job.params[s];
    job.wi = eval_job.out[0];
    job.weight = {d.out.data() + 3 * d.n, eval_job.out[0].layout, eval_job.out[0].row_stride};
    std::vector<float> pdf(d.n);
    std::vector<std::int32_t> lobe(d.n);
    job.pdf = pdf.data();
    job.lobe = lobe.data();
    const int threads = threads_of(state);
    for (auto _ : state) {
        pb::sample(job, d.n, threads, isa);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * d.n);
}

void simd_sample(benchmark::State& state, std::string isa, bool soa, bool per_element) {
    simd_sample_job(state, isa, make_job(data_for(state.range(0)), soa, per_element));
}

// The material set's samples.
void simd_sample_material(benchmark::State& state, std::string isa, int index) {
    simd_sample_job(state, isa, make_material_job(data_for(state.range(0)), index));
}

// The models over their domains (bench/RESULTS.md, "The 2015 BSDF"): a rough
// glass-like uniform material (the benchmark material's base color, roughness
// 0.3, specular 0.5) with spec_trans 0, 0.5 or 1, on pairs over the upper
// hemisphere or the whole sphere, and that glass with its energy compensation
// (pb.eval(..., energy_compensation=True)); one thread.
struct ModelCase {
    const char* name;
    pb::Model model;
    float spec_trans;
    bool sphere;
    bool compensated = false;
};
constexpr ModelCase kModelCases[] = {
    {"disney2014/upper", pb::Model::kDisney2014, 0.0f, false},
    {"disney2015/upper/spec_trans_0", pb::Model::kDisney2015, 0.0f, false},
    {"disney2015/sphere/spec_trans_0", pb::Model::kDisney2015, 0.0f, true},
    {"disney2015/sphere/spec_trans_0.5", pb::Model::kDisney2015, 0.5f, true},
    {"disney2015/sphere/spec_trans_1", pb::Model::kDisney2015, 1.0f, true},
    {"disney2015/sphere/spec_trans_1/compensated", pb::Model::kDisney2015, 1.0f, true, true},
};

pb::EvalJob make_model_job(Data& d, const ModelCase& c) {
    pb::EvalJob job = make_job(d, false, false);
    job.model = c.model;
    job.params[pb::kSubsurface].value = 0.0f;  // (the 2015 models read flatness instead)
    job.params[pb::kRoughness].value = 0.3f;
    job.params[pb::kSpecTrans].value = c.spec_trans;
    job.energy_compensation = c.compensated;
    return job;
}

void eval_model(benchmark::State& state, std::string isa, int index) {
    const ModelCase& c = kModelCases[index];
    Data& d = data_for(state.range(0), c.sphere);
    pb::EvalJob job = make_model_job(d, c);
    for (auto _ : state) {
        pb::eval(job, d.n, 1, isa);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * d.n);
}

void sample_model(benchmark::State& state, std::string isa, int index) {
    const ModelCase& c = kModelCases[index];
    pb::EvalJob job = make_model_job(data_for(state.range(0), c.sphere), c);
    simd_sample_job(state, isa, job, c.model);
}

void reference_eval(benchmark::State& state) {
    Data& d = data_for(state.range(0));
    pb::reference::Material m;
    m.roughness = 0.4;
    m.clearcoat = 0.5;
    m.sheen = 0.2;
    const auto row = m.slots();
    for (auto _ : state) {
        // as pb.reference.eval runs a uniform material: its shading prepared once per call
        pb::reference::ShadingCache shading;
        for (std::int64_t i = 0; i < d.n; ++i) {
            const Eigen::Vector3d wi(d.wi_aos[3 * i], d.wi_aos[3 * i + 1], d.wi_aos[3 * i + 2]);
            const Eigen::Vector3d wo(d.wo_aos[3 * i], d.wo_aos[3 * i + 1], d.wo_aos[3 * i + 2]);
            const Eigen::Vector3d f = pb::reference::eval(shading.of(row.data()), wi, wo);
            d.out[3 * i] = static_cast<float>(f.x());
            d.out[3 * i + 1] = static_cast<float>(f.y());
            d.out[3 * i + 2] = static_cast<float>(f.z());
        }
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * d.n);
}

void native_loop(benchmark::State& state, bool soa) {
    Data& d = data_for(state.range(0));
    const pb::bench::NativeMaterial m{{0.82f, 0.67f, 0.16f}, 0.2f, 0.3f, 0.5f, 0.1f, 0.4f, 0.3f, 0.2f, 0.5f, 0.5f, 0.7f};
    for (auto _ : state) {
        if (soa) {
            pb::bench::native_eval_rows(m, d.wi_soa.data(), d.wo_soa.data(), d.out.data(), d.n);
        } else {
            pb::bench::native_eval_interleaved(m, d.wi_aos.data(), d.wo_aos.data(), d.out.data(), d.n);
        }
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * d.n);
}

// Reads wi and wo, writes 3 floats per pair: the bytes eval moves; streaming:
// by non-temporal stores, as eval writes a call's f past 32 MB.
void copy_kernel(benchmark::State& state, bool streaming) {
    Data& d = data_for(state.range(0));
    const int threads = threads_of(state);
    for (auto _ : state) {
        pb::add_pairs(d.wi_aos.data(), d.wo_aos.data(), d.out.data(), d.n, threads, streaming);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * d.n);
}

void register_all() {
    const int all = pb::hardware_threads();
    // The reference is per element and slow: one size in cache, one beyond.
    for (std::int64_t n : {kSizes[0], kSizes[1]})
        benchmark::RegisterBenchmark("reference_f64", reference_eval)->Args({n, 1})->Unit(benchmark::kMicrosecond);
    for (const std::string& isa : pb::available_isas()) {
        for (std::int64_t n : kSizes) {
            for (int threads : {1, all}) {
                if (threads == all && all == 1) continue;
                for (bool soa : {false, true}) {
                    for (bool per_element : {false, true}) {
                        const std::string name = "eval/" + isa + (soa ? "/soa" : "/aos") +
                                                 (per_element ? "/per_element" : "/uniform");
                        benchmark::RegisterBenchmark(name.c_str(), simd_eval, isa, soa, per_element, false, pb::Output::kTotal)
                            ->Args({n, threads})
                            ->UseRealTime()
                            ->Unit(benchmark::kMicrosecond);
                        if (!soa && !per_element) {  // the default call: the direction check on
                            const std::string checked_name = "eval_checked/" + isa + "/aos/uniform";
                            benchmark::RegisterBenchmark(checked_name.c_str(), simd_eval, isa, false, false, true, pb::Output::kTotal)
                                ->Args({n, threads})
                                ->UseRealTime()
                                ->Unit(benchmark::kMicrosecond);
                        }
                        if (n == kSizes[0] && threads == 1) {
                            // also at 1024 pairs, where the Jacobian (156 bytes a pair) stays in L2, beside eval there
                            benchmark::RegisterBenchmark(name.c_str(), simd_eval, isa, soa, per_element, false, pb::Output::kTotal)
                                ->Args({kGradientInCache, 1})
                                ->UseRealTime()
                                ->Unit(benchmark::kMicrosecond);
                            const std::string grad_name = "eval_grad/" + isa + (soa ? "/soa" : "/aos") +
                                                          (per_element ? "/per_element" : "/uniform");
                            for (std::int64_t size : {kGradientInCache, n})
                                benchmark::RegisterBenchmark(grad_name.c_str(), simd_eval, isa, soa, per_element, false,
                                                             pb::Output::kGradient)
                                    ->Args({size, threads})
                                    ->UseRealTime()
                                    ->Unit(benchmark::kMicrosecond);
                        }
                        if (n == kSizes[0] && threads == 1 && !soa) {  // f with the energy compensation, beside eval
                            const std::string compensated_name = "eval_compensated/" + isa + "/aos" +
                                                                 (per_element ? "/per_element" : "/uniform");
                            benchmark::RegisterBenchmark(compensated_name.c_str(), simd_eval_compensated, isa, soa, per_element)
                                ->Args({n, threads})
                                ->UseRealTime()
                                ->Unit(benchmark::kMicrosecond);
                        }
                        if (n == kSizes[0] && threads == 1 && !soa) {  // f and the pdf in one pass
                            const std::string value_pdf_name = "eval_pdf/" + isa + "/aos" +
                                                               (per_element ? "/per_element" : "/uniform");
                            benchmark::RegisterBenchmark(value_pdf_name.c_str(), simd_eval, isa, soa, per_element, false,
                                                         pb::Output::kValuePdf)
                                ->Args({n, threads})
                                ->UseRealTime()
                                ->Unit(benchmark::kMicrosecond);
                        }
                        if (n == kSizes[0] && threads == 1 && !soa) {
                            const std::string sample_name = "sample/" + isa + "/aos" +
                                                            (per_element ? "/per_element" : "/uniform");
                            benchmark::RegisterBenchmark(sample_name.c_str(), simd_sample, isa, soa, per_element)
                                ->Args({n, threads})
                                ->UseRealTime()
                                ->Unit(benchmark::kMicrosecond);
                        }
                    }
                }
            }
        }
    }
    // the material set: in cache on one thread, unchecked; 16M pairs on every thread, checked (the
    // default call), beside the copy at the same size
    for (const std::string& isa : pb::available_isas()) {
        const int count = static_cast<int>(std::size(bench::kMaterials));
        for (int index = -1; index < count; ++index) {
            const std::string material = index < 0 ? "random_per_element" : bench::kMaterials[index].name;
            const std::string name = "eval_material/" + isa + "/aos/" + material;
            benchmark::RegisterBenchmark(name.c_str(), simd_eval_material, isa, index, false, false)
                ->Args({kSizes[0], 1})
                ->UseRealTime()
                ->Unit(benchmark::kMicrosecond);
            const std::string compensated_name = "eval_material_compensated/" + isa + "/aos/" + material;
            benchmark::RegisterBenchmark(compensated_name.c_str(), simd_eval_material, isa, index, false, true)
                ->Args({kSizes[0], 1})
                ->UseRealTime()
                ->Unit(benchmark::kMicrosecond);
            benchmark::RegisterBenchmark(("sample_material/" + isa + "/aos/" + material).c_str(), simd_sample_material, isa,
                                         index)
                ->Args({kSizes[0], 1})
                ->UseRealTime()
                ->Unit(benchmark::kMicrosecond);
            benchmark::RegisterBenchmark((name + "/checked").c_str(), simd_eval_material, isa, index, true, false)
                ->Args({kSizes[2], all})
                ->UseRealTime()
                ->Unit(benchmark::kMicrosecond);
        }
    }
    for (const std::string& isa : pb::available_isas()) {
        for (std::int64_t n : kSizes) {
            for (int index = 0; index < static_cast<int>(std::size(kModelCases)); ++index) {
                const std::string name = isa + "/" + kModelCases[index].name;
                benchmark::RegisterBenchmark(("eval_model/" + name).c_str(), eval_model, isa, index)
                    ->Args({n, 1})
                    ->Unit(benchmark::kMicrosecond);
                benchmark::RegisterBenchmark(("sample_model/" + name).c_str(), sample_model, isa, index)
                    ->Args({n, 1})
                    ->Unit(benchmark::kMicrosecond);
            }
        }
    }
    for (std::int64_t n : kSizes) {
        benchmark::RegisterBenchmark("native_loop/aos", native_loop, false)->Args({n, 1})->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("native_loop/soa", native_loop, true)->Args({n, 1})->Unit(benchmark::kMicrosecond);
        for (int threads : {1, all}) {
            benchmark::RegisterBenchmark("copy", copy_kernel, false)->Args({n, threads})->UseRealTime()->Unit(benchmark::kMicrosecond);
            benchmark::RegisterBenchmark("copy_streaming", copy_kernel, true)->Args({n, threads})->UseRealTime()->Unit(benchmark::kMicrosecond);
        }
    }
}

}  // namespace

int main(int argc, char** argv) {
    register_all();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
