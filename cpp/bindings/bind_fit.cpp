// Bindings for the fitting solver (principled_brdf/fit.py, docs/fitting.md):
// the normal equations of many problems in one pass of the kernels, and the
// damped, bounded step of each problem from them.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "principled_brdf/batch.hpp"

namespace py = pybind11;

namespace principled_brdf::bindings {
namespace {

using Float32Array = py::array_t<float, py::array::c_style>;
using Float64Array = py::array_t<double, py::array::c_style>;
using Int64Array = py::array_t<std::int64_t, py::array::c_style>;

void require_shape(const py::array& a, const std::vector<py::ssize_t>& shape, const char* name) {
    bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
    for (std::size_t k = 0; ok && k < shape.size(); ++k) ok = a.shape(k) == shape[k];
    if (!ok) throw std::invalid_argument(std::string(name) + ": array of the wrong shape");
}

// (normal, gradient, cost) of problems[j] (NormalEquationsJob, batch.hpp):
// (count, P (P + 1) / 2), (count, P) and (count,) float64 arrays; `slots`
// (B, gradient_slots(model)) the problems' materials.
py::tuple normal_equations(const Float32Array& wi, const Float32Array& wo, const Float32Array& slots,
                           const Float32Array& target, const Float32Array& scale, const Int64Array& problems,
                           const py::object& columns, int loss, bool cosine, int model, int threads, const std::string& isa,
                           const py::object& gain) {
    if (target.ndim() != 3 || target.shape(2) != 3) throw std::invalid_argument("target: expected a (B, N, 3) array");
    const py::ssize_t count = target.shape(0), pairs = target.shape(1);
    const Model which_model = model_from(model);
    require_shape(scale, {count, pairs, 3}, "scale");
    require_shape(slots, {count, gradient_slots(which_model)}, "slots");
    const bool per_problem = wi.ndim() == 3;
    for (const Float32Array* w : {&wi, &wo}) {
        if (per_problem) {
            require_shape(*w, {count, pairs, 3}, "wi, wo");
        } else {
            require_shape(*w, {pairs, 3}, "wi, wo");
        }
    }
    if (wo.ndim() != wi.ndim()) throw std::invalid_argument("wi, wo: expected the same shape");
    Float32Array gains;
    if (!gain.is_none()) {
        gains = py::cast<Float32Array>(gain);
        require_shape(gains, {count}, "gain");
    }
    if (problems.ndim() != 1) throw std::invalid_argument("problems: expected a 1-d array of problem indices");
    const py::ssize_t n = problems.shape(0);
    for (py::ssize_t j = 0; j < n; ++j)
        if (problems.data()[j] < 0 || problems.data()[j] >= count)
            throw std::invalid_argument("problems: index out of range");
    if (loss != static_cast<int>(Loss::kLinear) && loss != static_cast<int>(Loss::kLog))
        throw std::invalid_argument("loss: expected 0 (linear) or 1 (log)");
    NormalEquationsJob job;
    job.wi = wi.data();
    job.wo = wo.data();
    job.per_problem_directions = per_problem;
    job.pairs = pairs;
    job.slots = slots.data();
    job.target = target.data();
    job.scale = scale.data();
    job.gain = gain.is_none() ? nullptr : gains.data();
    job.problems = problems.data();
    job.model = which_model;
    job.loss = static_cast<Loss>(loss);
    job.cosine = cosine;
    job.columns = columns_from(columns, job.model);
    const py::ssize_t width = job.columns.count;
    Float64Array normal({n, width * (width + 1) / 2}), gradient({n, width}), cost({n});
    job.normal = normal.mutable_data();
    job.gradient = gradient.mutable_data();
    job.cost = cost.mutable_data();
    if (n > 0) {
        py::gil_scoped_release release;
        principled_brdf::normal_equations(job, n, threads, isa);
    }
    return py::make_tuple(normal, gradient, cost);
}

// Each problem's step δ solving (A + diag(damping)) δ = -g over its free
// parameters (δ = 0 for the others), A the upper triangle by rows of
// `normal`: a Cholesky factorisation per problem, in float64, in one fixed
// order. A problem whose damped matrix is not positive definite gets NaN.
Float64Array damped_steps(const Float64Array& normal, const Float64Array& gradient, const Float64Array& damping,
                          const py::array_t<bool, py::array::c_style>& free) {
    if (gradient.ndim() != 2) throw std::invalid_argument("gradient: expected a (B, P) array");
    const py::ssize_t count = gradient.shape(0), width = gradient.shape(1);
    require_shape(normal, {count, width * (width + 1) / 2}, "normal");
    require_shape(damping, {count, width}, "damping");
    require_shape(free, {count, width}, "free");
    Float64Array steps({count, width});
    double* out = steps.mutable_data();
    {
        py::gil_scoped_release release;
        std::vector<double> a(width * width), x(width);
        std::vector<int> index(width);
        for (py::ssize_t b = 0; b < count; ++b) {
            const double* packed = normal.data() + b * (width * (width + 1) / 2);
            const double* g = gradient.data() + b * width;
            const double* d = damping.data() + b * width;
            const bool* is_free = free.data() + b * width;
            double* step = out + b * width;
            int m = 0;  // the free parameters, in order
            for (py::ssize_t k = 0; k < width; ++k) {
                step[k] = 0.0;
                if (is_free[k]) index[m++] = static_cast<int>(k);
            }
            auto entry = [&](int k, int l) {  // A_kl from the upper triangle
                if (k > l) std::swap(k, l);
                return packed[k * width - k * (k - 1) / 2 + (l - k)];
            };
            bool ok = true;
            // lower Cholesky factor L of the free block, in a's lower triangle
            for (int i = 0; i < m && ok; ++i) {
                for (int j = 0; j <= i; ++j) {
                    double sum = entry(index[i], index[j]) + (i == j ? d[index[i]] : 0.0);
                    for (int k = 0; k < j; ++k) sum -= a[i * width + k] * a[j * width + k];
                    if (i == j) {
                        if (!(sum > 0.0) || !std::isfinite(sum)) {
                            ok = false;
                            break;
                        }
                        a[i * width + i] = std::sqrt(sum);
                    } else {
                        a[i * width + j] = sum / a[j * width + j];
                    }
                }
            }
            if (!ok) {
                for (py::ssize_t k = 0; k < width; ++k) step[k] = std::numeric_limits<double>::quiet_NaN();
                continue;
            }
            for (int i = 0; i < m; ++i) {  // L y = -g
                double sum = -g[index[i]];
                for (int k = 0; k < i; ++k) sum -= a[i * width + k] * x[k];
                x[i] = sum / a[i * width + i];
            }
            for (int i = m - 1; i >= 0; --i) {  // Lᵀ δ = y
                double sum = x[i];
                for (int k = i + 1; k < m; ++k) sum -= a[k * width + i] * x[k];
                x[i] = sum / a[i * width + i];
            }
            for (int i = 0; i < m; ++i) step[index[i]] = x[i];
        }
    }
    return steps;
}

}  // namespace

void bind_fit(py::module_& m) {
    m.def("normal_equations", &normal_equations, py::kw_only(), py::arg("wi"), py::arg("wo"), py::arg("slots"),
          py::arg("target"), py::arg("scale"), py::arg("problems"), py::arg("columns"), py::arg("loss"),
          py::arg("cosine"), py::arg("model"), py::arg("threads") = 0, py::arg("isa") = "", py::arg("gain") = py::none(),
          "(normal, gradient, cost) of the residuals (u(gain f) - target) scale of each listed problem, by the SIMD "
          "kernels: JᵀJ's upper triangle by rows, Jᵀr and Σ r² (float64).");
    m.def("damped_steps", &damped_steps, py::arg("normal"), py::arg("gradient"), py::arg("damping"), py::arg("free"),
          "Per problem, δ solving (A + diag(damping)) δ = -gradient over the free parameters (0 for the others; "
          "NaN where the damped matrix is not positive definite).");
}

}  // namespace principled_brdf::bindings
