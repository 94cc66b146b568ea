// Bindings for the parameter table and the float64 reference. The Python side
// (principled_brdf/reference.py) validates and broadcasts; these functions
// take flat, C-contiguous float64 arrays of matching length.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "principled_brdf/params.hpp"
#include "principled_brdf/reference.hpp"
#include "principled_brdf/reference_directions.hpp"

namespace py = pybind11;

namespace principled_brdf::bindings {

using Float64Array = py::array_t<double, py::array::c_style>;

namespace {

// The names of the members of `set` among `names`, in their order.
template <std::size_t N>
py::tuple names_in(BitSet set, const std::array<const char*, N>& names) {
    py::list members;
    for (std::size_t k = 0; k < N; ++k)
        if (contains(set, static_cast<int>(k))) members.append(names[k]);
    return py::tuple(members);
}

// A row of the model table as Python reads it (python/principled_brdf/_models.py).
py::dict model_row(const ModelRow& row) {
    std::array<const char*, kParams.size()> parameter_names{};
    for (std::size_t k = 0; k < kParams.size(); ++k) parameter_names[k] = kParams[k].name;
    py::dict d;
    d["name"] = row.name;
    d["whole_sphere"] = row.whole_sphere;
    d["reads"] = names_in(row.reads, parameter_names);
    d["gradient_slots"] = row.gradient_slots;
    d["lobes"] = names_in(row.lobes, kLobeNames);
    d["sampled_lobes"] = names_in(row.sampled_lobes, kSampledLobeNames);
    d["energy_compensation"] = row.energy_compensation;
    d["max_ior"] = row.max_ior;
    d["max_specular"] = max_specular(row);
    return d;
}

}  // namespace

void bind_params(py::module_& m) {
    py::list table;
    for (const ParamInfo& info : kParams) {
        py::tuple defaults(info.slots);
        for (int i = 0; i < info.slots; ++i) defaults[i] = info.default_value[i];
        table.append(py::make_tuple(info.name, info.first_slot, info.slots, defaults, info.lower, info.upper));
    }
    m.attr("PARAMETER_TABLE") = table;
    m.attr("PARAM_SLOTS") = static_cast<int>(kParamSlots);
    auto names = [](const auto& table) {
        py::tuple tuple(table.size());
        for (std::size_t i = 0; i < table.size(); ++i) tuple[i] = table[i];
        return tuple;
    };
    py::tuple model_names(kModels.size()), model_table(kModels.size());
    for (std::size_t i = 0; i < kModels.size(); ++i) {
        model_names[i] = kModels[i].name;
        model_table[i] = model_row(kModels[i]);
    }
    m.attr("MODEL_NAMES") = model_names;
    m.attr("MODEL_TABLE") = model_table;
    m.attr("LOBE_NAMES") = names(kLobeNames);
    m.attr("SAMPLED_LOBE_NAMES") = names(kSampledLobeNames);
    m.attr("SAMPLER_NAMES") = names(kSpecularSamplerNames);
    m.attr("MODE_NAMES") = names(kTransportModeNames);
    m.attr("GRADIENT_SLOTS") = kGradientSlots;
}

namespace {

void require_rows(const Float64Array& a, py::ssize_t n, py::ssize_t columns, const char* name) {
    if (a.ndim() != 2 || a.shape(0) != n || a.shape(1) != columns)
        throw std::invalid_argument(std::string(name) + ": expected a contiguous (N, " + std::to_string(columns) +
                                    ") float64 array");
}

// The sampling functions take each input as N rows or as a single row shared by
// all N (a uniform material, one view direction): a packed (N, 16) copy of a
// uniform material would cost more than the samples.
struct Rows {
    const double* data;
    py::ssize_t stride;  // doubles between consecutive rows: columns, or 0 for a shared row
    const double* row(py::ssize_t i) const { return data + i * stride; }
};

py::ssize_t common_row_count(std::initializer_list<const Float64Array*> arrays) {
    py::ssize_t n = 1;
    for (const Float64Array* a : arrays)
        if (a->ndim() == 2 && a->shape(0) != 1) n = a->shape(0);
    return n;
}

Rows shared_or_rows(const Float64Array& a, py::ssize_t n, py::ssize_t columns, const char* name) {
    if (a.ndim() != 2 || a.shape(1) != columns || (a.shape(0) != n && a.shape(0) != 1))
        throw std::invalid_argument(std::string(name) + ": expected a contiguous (N, " + std::to_string(columns) +
                                    ") or (1, " + std::to_string(columns) + ") float64 array, N = " +
                                    std::to_string(n));
    return {a.data(), a.shape(0) == 1 ? 0 : columns};
}

// Calls f with a row cache of Compensated materials for the model's tables.
template <class Function>
void each_compensated(Model model, Function&& f) {
    if (model == Model::kDisney2012) {
        reference::CompensatedCache<Model::kDisney2012> cache;
        f(cache);
    } else {
        reference::CompensatedCache<Model::kDisney2014> cache;
        f(cache);
    }
}


// f (N,3) or the lobes (N,7,3) for N packed rows: wi (N,3), wo (N,3), params (N,16) or one shared row.
py::array_t<double> reference_eval(const Float64Array& wi, const Float64Array& wo, const Float64Array& params,
                                   int model, bool lobes, bool energy_compensation, int mode) {
    const py::ssize_t n = wi.ndim() == 2 ? wi.shape(0) : -1;
    require_rows(wi, n, 3, "wi");
    require_rows(wo, n, 3, "wo");
    const Rows material_rows = shared_or_rows(params, n, kParamSlots, "params");
    const Model which_model = model_from(model);

    std::vector<py::ssize_t> shape{n};
    if (lobes) shape.push_back(kLobeCount);
    shape.push_back(3);
    py::array_t<double> out(shape);
    const double* wi_data = wi.data();
    const double* wo_data = wo.data();
    double* out_data = out.mutable_data();
    {
        py::gil_scoped_release release;
        auto store = [&](py::ssize_t i, const reference::Lobes& result) {
            double* row = out_data + 3 * kLobeCount * i;
            Eigen::Map<Eigen::Vector3d>(row + 0) = result.diffuse;
            Eigen::Map<Eigen::Vector3d>(row + 3) = result.sheen;
            Eigen::Map<Eigen::Vector3d>(row + 6) = result.specular;
            Eigen::Map<Eigen::Vector3d>(row + 9) = result.clearcoat;
            Eigen::Map<Eigen::Vector3d>(row + 12) = result.multiple_scattering;
            Eigen::Map<Eigen::Vector3d>(row + 15) = result.transmission;
            Eigen::Map<Eigen::Vector3d>(row + 18) = result.diffuse_transmission;
        };
        if (is_bsdf(which_model)) {
            const TransportMode transport = mode_from(mode);
            reference::with_cache2015<reference::Shading2015Cache>(which_model, energy_compensation, [&](auto& shading) {
                for (py::ssize_t i = 0; i < n; ++i) {
                    const auto& material = shading.of(material_rows.row(i));
                    const Eigen::Vector3d in(wi_data + 3 * i), view(wo_data + 3 * i);
                    if (lobes) {
                        store(i, reference::eval_lobes(material, in, view, transport));
                    } else {
                        Eigen::Map<Eigen::Vector3d>(out_data + 3 * i) = reference::eval(material, in, view, transport);
                    }
                }
            });
        } else if (energy_compensation) {
            each_compensated(which_model, [&](auto& cache) {
                for (py::ssize_t i = 0; i < n; ++i) {
                    const auto& material = cache.of(material_rows.row(i));
                    const Eigen::Vector3d in(wi_data + 3 * i), view(wo_data + 3 * i);
                    if (lobes) {
                        store(i, reference::eval_lobes(material, in, view, which_model));
                    } else {
                        Eigen::Map<Eigen::Vector3d>(out_data + 3 * i) = reference::eval(material, in, view, which_model);
                    }
                }
            });
        } else {
            reference::ShadingCache shading;
            for (py::ssize_t i = 0; i < n; ++i) {
                const auto& material = shading.of(material_rows.row(i));
                const Eigen::Vector3d in(wi_data + 3 * i), view(wo_data + 3 * i);
                if (lobes) {
                    store(i, reference::eval_lobes(material, in, view, which_model));
                } else {
                    Eigen::Map<Eigen::Vector3d>(out_data + 3 * i) = reference::eval(material, in, view, which_model);
                }
            }
        }
    }
    return out;
}

// f (N,3) and its Jacobian (N,3,P), P = gradient_slots(model) (13, or 16 for the 2015 models), for N packed
// rows: wi (N,3), wo (N,3), params (N,16) or one shared row.
py::tuple reference_eval_grad(const Float64Array& wi, const Float64Array& wo, const Float64Array& params, int model,
                              int mode, bool energy_compensation) {
    const py::ssize_t n = wi.ndim() == 2 ? wi.shape(0) : -1;
    require_rows(wi, n, 3, "wi");
    require_rows(wo, n, 3, "wo");
    const Rows material_rows = shared_or_rows(params, n, kParamSlots, "params");
    const Model which_model = model_from(model);
    const TransportMode transport = mode_from(mode);
    const int slots = gradient_slots(which_model);
    py::array_t<double> value({n, py::ssize_t(3)}), jacobian({n, py::ssize_t(3), py::ssize_t(slots)});
    const double* wi_data = wi.data();
    const double* wo_data = wo.data();
    double* value_data = value.mutable_data();
    double* jacobian_data = jacobian.mutable_data();
    auto store = [&](py::ssize_t i, const auto& g) {
        Eigen::Map<Eigen::Vector3d>(value_data + 3 * i) = g.value;
        std::copy(g.jacobian.data(), g.jacobian.data() + 3 * slots, jacobian_data + 3 * slots * i);
    };
    {
        py::gil_scoped_release release;
        if (is_bsdf(which_model)) {
            auto run = [&](auto& prepared) {
                for (py::ssize_t i = 0; i < n; ++i) {
                    const Eigen::Vector3d in(wi_data + 3 * i), view(wo_data + 3 * i);
                    store(i, reference::eval_grad(prepared.of(material_rows.row(i)), in, view, transport));
                }
            };
            reference::with_cache2015<reference::GradientShading2015Cache>(which_model, energy_compensation, run);
        } else {
            reference::GradientShadingCache prepared;
            for (py::ssize_t i = 0; i < n; ++i) {
                const Eigen::Vector3d in(wi_data + 3 * i), view(wo_data + 3 * i);
                store(i, reference::eval_grad(prepared.of(material_rows.row(i)), in, view, which_model));
            }
        }
    }
    return py::make_tuple(value, jacobian);
}

// ∂f/∂(wi, wo) (N,3,6) for N packed rows as reference_eval_grad's, f times |cos θl| if cosine.
py::array_t<double> reference_eval_direction_grad(const Float64Array& wi, const Float64Array& wo,
                                                  const Float64Array& params, int model, bool cosine, int mode,
                                                  bool energy_compensation) {
    const py::ssize_t n = wi.ndim() == 2 ? wi.shape(0) : -1;
    require_rows(wi, n, 3, "wi");
    require_rows(wo, n, 3, "wo");
    const Rows material_rows = shared_or_rows(params, n, kParamSlots, "params");
    const Model which_model = model_from(model);
    const TransportMode transport = mode_from(mode);
    py::array_t<double> jacobian({n, py::ssize_t(3), py::ssize_t(reference::kDirectionSlots)});
    const double* wi_data = wi.data();
    const double* wo_data = wo.data();
    double* jacobian_data = jacobian.mutable_data();
    auto run = [&](auto& prepared, auto&& gradient_of) {
        for (py::ssize_t i = 0; i < n; ++i) {
            const Eigen::Vector3d in(wi_data + 3 * i), view(wo_data + 3 * i);
            const reference::DirectionGradient g = gradient_of(prepared.of(material_rows.row(i)), in, view);
            std::copy(g.jacobian.data(), g.jacobian.data() + 3 * reference::kDirectionSlots, jacobian_data + 3 * reference::kDirectionSlots * i);
        }
    };
    auto bsdf = [&](const auto& s, const Eigen::Vector3d& in, const Eigen::Vector3d& view) {
        return reference::eval_direction_grad(s, in, view, cosine, transport);
    };
    {
        py::gil_scoped_release release;
        if (is_bsdf(which_model)) {
            reference::with_cache2015<reference::DirectionShading2015Cache>(which_model, energy_compensation,
                                                                             [&](auto& prepared) { run(prepared, bsdf); });
        } else {
            reference::DirectionShadingCache prepared;
            run(prepared, [&](const auto& s, const Eigen::Vector3d& in, const Eigen::Vector3d& view) {
                return reference::eval_direction_grad(s, in, view, which_model, cosine);
            });
        }
    }
    return jacobian;
}

// docs/sampling.md: wo (N,3), u (N,3) = (u0, u1, u2), params (N,16); each may be one shared row.
py::tuple reference_sample(const Float64Array& wo, const Float64Array& u, const Float64Array& params, int model,
                           int sampler, bool energy_compensation, int mode) {
    const py::ssize_t n = common_row_count({&wo, &u, &params});
    const Rows view = shared_or_rows(wo, n, 3, "wo");
    const Rows uniforms = shared_or_rows(u, n, 3, "u");
    const Rows material_rows = shared_or_rows(params, n, kParamSlots, "params");
    const Model which_model = model_from(model);
    const SpecularSampler which_sampler = sampler_from(sampler);

    py::array_t<double> wi_out({n, py::ssize_t(3)}), pdf_out(n), weight_out({n, py::ssize_t(3)});
    py::array_t<std::int32_t> lobe_out(n);
    double* wi_data = wi_out.mutable_data();
    double* pdf_data = pdf_out.mutable_data();
    double* weight_data = weight_out.mutable_data();
    std::int32_t* lobe_data = lobe_out.mutable_data();
    {
        py::gil_scoped_release release;
        auto store = [&](py::ssize_t i, const reference::Sample& s) {
            Eigen::Map<Eigen::Vector3d>(wi_data + 3 * i) = s.wi;
            pdf_data[i] = s.pdf;
            Eigen::Map<Eigen::Vector3d>(weight_data + 3 * i) = s.weight;
            lobe_data[i] = s.lobe;
        };
        auto run = [&](auto& cache) {
            for (py::ssize_t i = 0; i < n; ++i) {
                const double* ui = uniforms.row(i);
                store(i, reference::sample(cache.of(material_rows.row(i)), Eigen::Vector3d(view.row(i)), ui[0], ui[1], ui[2],
                                           which_model, which_sampler));
            }
        };
        if (is_bsdf(which_model)) {
            const TransportMode transport = mode_from(mode);
            reference::with_cache2015<reference::Shading2015Cache>(which_model, energy_compensation, [&](auto& shading) {
                for (py::ssize_t i = 0; i < n; ++i) {
                    const double* ui = uniforms.row(i);
                    store(i, reference::sample(shading.of(material_rows.row(i)), Eigen::Vector3d(view.row(i)), ui[0], ui[1],
                                               ui[2], which_sampler, transport));
                }
            });
        } else if (energy_compensation) {
            each_compensated(which_model, run);
        } else {
            reference::ShadingCache shading;
            run(shading);
        }
    }
    return py::make_tuple(wi_out, pdf_out, weight_out, lobe_out);
}

// The mixture pdf (N,) of wi (N,3) given wo (N,3): the 2012 and 2014 models share one (the
// compensation's tables aside), each 2015 model has its own over the whole sphere.
py::array_t<double> reference_pdf(const Float64Array& wi, const Float64Array& wo, const Float64Array& params,
                                  int model, int sampler, bool energy_compensation) {
    const py::ssize_t n = common_row_count({&wi, &wo, &params});
    const Rows in = shared_or_rows(wi, n, 3, "wi");
    const Rows view = shared_or_rows(wo, n, 3, "wo");
    const Rows material_rows = shared_or_rows(params, n, kParamSlots, "params");
    const Model which_model = model_from(model);  // for the BRDFs, only through the compensation's tables
    const SpecularSampler which_sampler = sampler_from(sampler);

    py::array_t<double> out(n);
    double* out_data = out.mutable_data();
    {
        py::gil_scoped_release release;
        auto run = [&](auto& cache) {
            for (py::ssize_t i = 0; i < n; ++i) {
                const auto& material = cache.of(material_rows.row(i));
                out_data[i] = reference::pdf(material, Eigen::Vector3d(in.row(i)), Eigen::Vector3d(view.row(i)),
                                             which_sampler);
            }
        };
        if (is_bsdf(which_model)) {
            reference::with_cache2015<reference::Shading2015Cache>(which_model, energy_compensation, run);
        } else if (energy_compensation) {
            each_compensated(which_model, run);
        } else {
            reference::ShadingCache shading;
            run(shading);
        }
    }
    return out;
}

// (P0, P1, P2) (N,3) at wo (N,3); for the 2015 models (N,5), the lobes of kSampledLobeNames.
py::array_t<double> reference_lobe_probabilities(const Float64Array& wo, const Float64Array& params, int model,
                                                 bool energy_compensation) {
    const py::ssize_t n = common_row_count({&wo, &params});
    const Rows view = shared_or_rows(wo, n, 3, "wo");
    const Rows material_rows = shared_or_rows(params, n, kParamSlots, "params");
    const py::ssize_t lobes = is_bsdf(model_from(model)) ? py::ssize_t(kSampledLobeNames.size()) : 3;
    py::array_t<double> out({n, lobes});
    double* out_data = out.mutable_data();
    {
        py::gil_scoped_release release;
        auto run = [&](auto& cache) {
            for (py::ssize_t i = 0; i < n; ++i) {
                const auto& material = cache.of(material_rows.row(i));
                const auto p = reference::lobe_probabilities(material, Eigen::Vector3d(view.row(i)));
                std::copy(p.begin(), p.end(), out_data + lobes * i);
            }
        };
        if (is_bsdf(model_from(model))) {
            reference::with_cache2015<reference::Shading2015Cache>(model_from(model), energy_compensation, run);
        } else if (energy_compensation) {
            each_compensated(model_from(model), run);
        } else {
            reference::ShadingCache shading;
            run(shading);
        }
    }
    return out;
}

}  // namespace

void bind_reference(py::module_& m) {
    m.def("reference_eval", &reference_eval, py::arg("wi"), py::arg("wo"), py::arg("params"), py::arg("model"),
          py::arg("lobes"), py::arg("energy_compensation") = false, py::arg("mode") = 0,
          "Float64 reference f (N,3) or lobes (N,7,3) for packed, already validated rows.");
    m.def("reference_eval_grad", &reference_eval_grad, py::arg("wi"), py::arg("wo"), py::arg("params"), py::arg("model"),
          py::arg("mode") = 0, py::arg("energy_compensation") = false,
          "Float64 reference f (N,3) and its Jacobian (N,3,P) over the model's P parameter slots, for packed validated rows.");
    m.def("reference_eval_direction_grad", &reference_eval_direction_grad, py::arg("wi"), py::arg("wo"), py::arg("params"),
          py::arg("model"), py::arg("cosine") = false, py::arg("mode") = 0, py::arg("energy_compensation") = false,
          "Float64 reference derivatives (N,3,6) of f (times |cos θl| if cosine) in wi_x, wi_y, wi_z, wo_x, wo_y, wo_z.");
    m.def("reference_sample", &reference_sample, py::arg("wo"), py::arg("u"), py::arg("params"), py::arg("model"),
          py::arg("sampler"), py::arg("energy_compensation") = false, py::arg("mode") = 0,
          "Float64 reference samples (wi (N,3), pdf (N,), weight (N,3), lobe (N,) int32) for validated rows;\n"
          "each input is N rows or one shared row.");
    m.def("reference_pdf", &reference_pdf, py::arg("wi"), py::arg("wo"), py::arg("params"), py::arg("model"),
          py::arg("sampler"), py::arg("energy_compensation") = false, "Float64 reference mixture pdf (N,) for validated rows (N or one shared row each).");
    m.def("reference_lobe_probabilities", &reference_lobe_probabilities, py::arg("wo"), py::arg("params"),
          py::arg("model") = 0, py::arg("energy_compensation") = false, "Lobe probabilities (N,3), (N,5) for the 2015 models, at wo for validated rows (N or one shared row each).");
}

}  // namespace principled_brdf::bindings
