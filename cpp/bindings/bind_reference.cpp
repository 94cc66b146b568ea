// Bindings for the parameter table and the float64 reference. The Python side
// (principled_brdf/reference.py) validates and broadcasts; these functions
// take flat, C-contiguous float64 arrays of matching length.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <stdexcept>

#include "bindings.hpp"
#include "principled_brdf/params.hpp"
#include "principled_brdf/reference.hpp"

namespace py = pybind11;

namespace principled_brdf::bindings {

using Float64Array = py::array_t<double, py::array::c_style>;

void bind_params(py::module_& m) {
    py::list table;
    for (const ParamInfo& info : kParams) {
        py::tuple defaults(info.slots);
        for (int i = 0; i < info.slots; ++i) defaults[i] = info.default_value[i];
        table.append(py::make_tuple(info.name, info.first_slot, info.slots, defaults, info.lower, info.upper));
    }
    m.attr("PARAMETER_TABLE") = table;
    m.attr("PARAM_SLOTS") = static_cast<int>(kParamSlots);
}

namespace {

void require_rows(const Float64Array& a, py::ssize_t n, py::ssize_t columns, const char* name) {
    if (a.ndim() != 2 || a.shape(0) != n || a.shape(1) != columns)
        throw std::invalid_argument(std::string(name) + ": expected a contiguous (N, " + std::to_string(columns) +
                                    ") float64 array");
}

// f or the four lobes for N packed rows: wi (N,3), wo (N,3), params (N,13).
py::array_t<double> reference_eval(const Float64Array& wi, const Float64Array& wo, const Float64Array& params,
                                   int model, bool lobes) {
    const py::ssize_t n = wi.ndim() == 2 ? wi.shape(0) : -1;
    require_rows(wi, n, 3, "wi");
    require_rows(wo, n, 3, "wo");
    require_rows(params, n, kParamSlots, "params");
    if (model != 0 && model != 1) throw std::invalid_argument("model: expected 0 (disney2014) or 1 (disney2012)");

    std::vector<py::ssize_t> shape{n};
    if (lobes) shape.push_back(4);
    shape.push_back(3);
    py::array_t<double> out(shape);
    const double* wi_data = wi.data();
    const double* wo_data = wo.data();
    const double* param_data = params.data();
    double* out_data = out.mutable_data();
    {
        py::gil_scoped_release release;
        for (py::ssize_t i = 0; i < n; ++i) {
            const auto material = reference::Material::from_slots(param_data + i * kParamSlots);
            const Eigen::Vector3d in(wi_data + 3 * i), view(wo_data + 3 * i);
            const auto result = reference::eval_lobes(material, in, view, static_cast<Model>(model));
            if (lobes) {
                double* row = out_data + 12 * i;
                Eigen::Map<Eigen::Vector3d>(row + 0) = result.diffuse;
                Eigen::Map<Eigen::Vector3d>(row + 3) = result.sheen;
                Eigen::Map<Eigen::Vector3d>(row + 6) = result.specular;
                Eigen::Map<Eigen::Vector3d>(row + 9) = result.clearcoat;
            } else {
                Eigen::Map<Eigen::Vector3d>(out_data + 3 * i) = result.total();
            }
        }
    }
    return out;
}

}  // namespace

void bind_reference(py::module_& m) {
    m.def("reference_eval", &reference_eval, py::arg("wi"), py::arg("wo"), py::arg("params"), py::arg("model"),
          py::arg("lobes"),
          "Float64 reference f (N,3) or lobes (N,4,3) for packed, already validated rows.");
}

}  // namespace principled_brdf::bindings
