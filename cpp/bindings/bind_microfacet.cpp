// Bindings for the microfacet toolkit (microfacet.hpp) as the submodule
// principled_brdf._core.microfacet. Each function is a loop over rows: every
// argument is a C-contiguous float64 array with either N rows or one row that
// all rows share (scalars (N,) or (1,), directions (N, 3) or (1, 3)). The
// Python side (principled_brdf/microfacet.py) validates and broadcasts;
// direction arguments are normalised here before the formulas see them.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "principled_brdf/microfacet.hpp"
#include "principled_brdf/microfacet_family.hpp"

namespace py = pybind11;

namespace principled_brdf::bindings {

namespace {

namespace mf = principled_brdf::microfacet;

using Float64Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// One argument: `width` doubles per row, N rows or a single shared row.
class Column {
public:
    Column(const Float64Array& array, int width, const char* name) : data_(array.data()), width_(width) {
        const bool shape_ok = width == 1 ? array.ndim() == 1 : (array.ndim() == 2 && array.shape(1) == width);
        if (!shape_ok)
            throw std::invalid_argument(std::string(name) + ": expected a contiguous " +
                                        (width == 1 ? "(N,)" : "(N, 3)") + " float64 array");
        rows_ = array.shape(0);
        name_ = name;
    }
    py::ssize_t rows() const { return rows_; }
    const char* name() const { return name_; }
    void bind_rows(py::ssize_t n) {
        if (rows_ != n && rows_ != 1)
            throw std::invalid_argument(std::string(name_) + ": expected " + std::to_string(n) + " or 1 rows, got " +
                                        std::to_string(rows_));
        stride_ = rows_ == 1 ? 0 : width_;
    }
    double scalar(py::ssize_t i) const { return data_[i * stride_]; }
    mf::Vec3 unit_vector(py::ssize_t i) const {
        const double* v = data_ + i * stride_;
        return mf::normalize({v[0], v[1], v[2]});
    }

private:
    const double* data_;
    int width_;
    py::ssize_t rows_ = 0;
    py::ssize_t stride_ = 0;
    const char* name_ = "";
};

// The common row count of the arguments: the first that is not 1 (the others must match it or be 1).
py::ssize_t common_rows(std::vector<Column*> columns) {
    py::ssize_t n = 1;
    for (const Column* c : columns)
        if (c->rows() != 1) {
            n = c->rows();
            break;
        }
    for (Column* c : columns) c->bind_rows(n);
    return n;
}

// out[i] = row_function(i) for i < n, with the GIL released around the loop.
template <class RowFunction>
py::array_t<double> scalar_rows(py::ssize_t n, RowFunction row_function) {
    py::array_t<double> out(n);
    double* out_data = out.mutable_data();
    {
        py::gil_scoped_release release;
        for (py::ssize_t i = 0; i < n; ++i) out_data[i] = row_function(i);
    }
    return out;
}

template <class RowFunction>
py::array_t<double> vector_rows(py::ssize_t n, RowFunction row_function) {
    py::array_t<double> out({n, py::ssize_t{3}});
    double* out_data = out.mutable_data();
    {
        py::gil_scoped_release release;
        for (py::ssize_t i = 0; i < n; ++i) {
            const mf::Vec3 v = row_function(i);
            out_data[3 * i + 0] = v.x;
            out_data[3 * i + 1] = v.y;
            out_data[3 * i + 2] = v.z;
        }
    }
    return out;
}

// f(w, alpha_x, alpha_y) -> scalar, for D, pdf, Λ and G1 of GGX and Beckmann.
template <double (*Formula)(const mf::Vec3&, double, double)>
py::array_t<double> direction_alphas(const Float64Array& w, const Float64Array& alpha_x, const Float64Array& alpha_y) {
    Column wc(w, 3, "w"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y");
    const py::ssize_t n = common_rows({&wc, &ax, &ay});
    return scalar_rows(n, [&](py::ssize_t i) { return Formula(wc.unit_vector(i), ax.scalar(i), ay.scalar(i)); });
}

// f(a, b, alpha_x, alpha_y) -> scalar, for G2 and the visible-normal pdf.
template <double (*Formula)(const mf::Vec3&, const mf::Vec3&, double, double)>
py::array_t<double> two_directions_alphas(const Float64Array& a, const Float64Array& b, const Float64Array& alpha_x,
                                          const Float64Array& alpha_y) {
    Column ac(a, 3, "a"), bc(b, 3, "b"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y");
    const py::ssize_t n = common_rows({&ac, &bc, &ax, &ay});
    return scalar_rows(
        n, [&](py::ssize_t i) { return Formula(ac.unit_vector(i), bc.unit_vector(i), ax.scalar(i), ay.scalar(i)); });
}

// h = sample(u1, u2, alpha_x, alpha_y), for the GGX and Beckmann distribution samplers.
template <mf::Vec3 (*Sampler)(double, double, double, double)>
py::array_t<double> sample_alphas(const Float64Array& u1, const Float64Array& u2, const Float64Array& alpha_x,
                                  const Float64Array& alpha_y) {
    Column c1(u1, 1, "u1"), c2(u2, 1, "u2"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y");
    const py::ssize_t n = common_rows({&c1, &c2, &ax, &ay});
    return vector_rows(n,
                       [&](py::ssize_t i) { return Sampler(c1.scalar(i), c2.scalar(i), ax.scalar(i), ay.scalar(i)); });
}

// f(cos θ, η[, k]) -> scalar: the Fresnel factors.
py::array_t<double> fresnel_dielectric(const Float64Array& cos_theta, const Float64Array& eta) {
    Column c(cos_theta, 1, "cos_theta"), e(eta, 1, "eta");
    const py::ssize_t n = common_rows({&c, &e});
    return scalar_rows(n, [&](py::ssize_t i) { return mf::fresnel_dielectric(c.scalar(i), e.scalar(i)); });
}

py::array_t<double> fresnel_conductor(const Float64Array& cos_theta, const Float64Array& eta, const Float64Array& k) {
    Column c(cos_theta, 1, "cos_theta"), e(eta, 1, "eta"), kc(k, 1, "k");
    const py::ssize_t n = common_rows({&c, &e, &kc});
    return scalar_rows(n, [&](py::ssize_t i) { return mf::fresnel_conductor(c.scalar(i), e.scalar(i), kc.scalar(i)); });
}

py::array_t<double> refract(const Float64Array& w, const Float64Array& eta) {
    Column wc(w, 3, "w"), e(eta, 1, "eta");
    const py::ssize_t n = common_rows({&wc, &e});
    return vector_rows(n, [&](py::ssize_t i) { return mf::refract(wc.unit_vector(i), e.scalar(i)); });
}

py::array_t<double> generalized_half_vector(const Float64Array& wi, const Float64Array& wo, const Float64Array& eta) {
    Column a(wi, 3, "wi"), b(wo, 3, "wo"), e(eta, 1, "eta");
    const py::ssize_t n = common_rows({&a, &b, &e});
    return vector_rows(n, [&](py::ssize_t i) {
        return mf::generalized_half_vector(a.unit_vector(i), b.unit_vector(i), e.scalar(i));
    });
}

py::array_t<double> refraction_jacobian(const Float64Array& wi, const Float64Array& wo, const Float64Array& eta) {
    Column a(wi, 3, "wi"), b(wo, 3, "wo"), e(eta, 1, "eta");
    const py::ssize_t n = common_rows({&a, &b, &e});
    return scalar_rows(n, [&](py::ssize_t i) {
        return mf::refraction_jacobian(a.unit_vector(i), b.unit_vector(i), e.scalar(i));
    });
}

py::array_t<double> gtr_d(const Float64Array& cos_theta_h, const Float64Array& alpha, const Float64Array& gamma,
                          bool closed_forms) {
    Column c(cos_theta_h, 1, "cos_theta_h"), a(alpha, 1, "alpha"), g(gamma, 1, "gamma");
    const py::ssize_t n = common_rows({&c, &a, &g});
    return scalar_rows(n,
                       [&](py::ssize_t i) { return mf::gtr_d(c.scalar(i), a.scalar(i), g.scalar(i), closed_forms); });
}

py::array_t<double> gtr_pdf(const Float64Array& h, const Float64Array& alpha, const Float64Array& gamma,
                            bool closed_forms) {
    Column hc(h, 3, "h"), a(alpha, 1, "alpha"), g(gamma, 1, "gamma");
    const py::ssize_t n = common_rows({&hc, &a, &g});
    return scalar_rows(
        n, [&](py::ssize_t i) { return mf::gtr_pdf_h(hc.unit_vector(i), a.scalar(i), g.scalar(i), closed_forms); });
}

py::array_t<double> gtr_sample(const Float64Array& u1, const Float64Array& u2, const Float64Array& alpha,
                               const Float64Array& gamma, bool closed_forms) {
    Column c1(u1, 1, "u1"), c2(u2, 1, "u2"), a(alpha, 1, "alpha"), g(gamma, 1, "gamma");
    const py::ssize_t n = common_rows({&c1, &c2, &a, &g});
    return vector_rows(n, [&](py::ssize_t i) {
        return mf::gtr_sample_h(c1.scalar(i), c2.scalar(i), a.scalar(i), g.scalar(i), closed_forms);
    });
}

py::array_t<double> ggx_sample_visible(const Float64Array& wo, const Float64Array& u1, const Float64Array& u2,
                                       const Float64Array& alpha_x, const Float64Array& alpha_y) {
    Column w(wo, 3, "wo"), c1(u1, 1, "u1"), c2(u2, 1, "u2"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y");
    const py::ssize_t n = common_rows({&w, &c1, &c2, &ax, &ay});
    return vector_rows(n, [&](py::ssize_t i) {
        return mf::ggx_sample_visible_h(w.unit_vector(i), c1.scalar(i), c2.scalar(i), ax.scalar(i), ay.scalar(i));
    });
}

// ---- the microfacet family (microfacet_family.hpp): each function also takes the shape parameter
// (Student-t γ, exponential-power p; ignored by Blinn-Phong and Walter's Beckmann)

template <double (*Formula)(const mf::Vec3&, double, double, double)>
py::array_t<double> direction_alphas_shape(const Float64Array& w, const Float64Array& alpha_x,
                                           const Float64Array& alpha_y, const Float64Array& shape) {
    Column wc(w, 3, "w"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y"), sc(shape, 1, "shape");
    const py::ssize_t n = common_rows({&wc, &ax, &ay, &sc});
    return scalar_rows(
        n, [&](py::ssize_t i) { return Formula(wc.unit_vector(i), ax.scalar(i), ay.scalar(i), sc.scalar(i)); });
}

template <double (*Formula)(const mf::Vec3&, const mf::Vec3&, double, double, double)>
py::array_t<double> two_directions_alphas_shape(const Float64Array& a, const Float64Array& b,
                                                const Float64Array& alpha_x, const Float64Array& alpha_y,
                                                const Float64Array& shape) {
    Column ac(a, 3, "a"), bc(b, 3, "b"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y"), sc(shape, 1, "shape");
    const py::ssize_t n = common_rows({&ac, &bc, &ax, &ay, &sc});
    return scalar_rows(n, [&](py::ssize_t i) {
        return Formula(ac.unit_vector(i), bc.unit_vector(i), ax.scalar(i), ay.scalar(i), sc.scalar(i));
    });
}

template <mf::Vec3 (*Sampler)(double, double, double, double, double)>
py::array_t<double> sample_alphas_shape(const Float64Array& u1, const Float64Array& u2, const Float64Array& alpha_x,
                                        const Float64Array& alpha_y, const Float64Array& shape) {
    Column c1(u1, 1, "u1"), c2(u2, 1, "u2"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y"),
        sc(shape, 1, "shape");
    const py::ssize_t n = common_rows({&c1, &c2, &ax, &ay, &sc});
    return vector_rows(n, [&](py::ssize_t i) {
        return Sampler(c1.scalar(i), c2.scalar(i), ax.scalar(i), ay.scalar(i), sc.scalar(i));
    });
}

py::array_t<double> ggx_g2_over_4cos(const Float64Array& wi, const Float64Array& wo, const Float64Array& alpha_x,
                                     const Float64Array& alpha_y, int form) {
    if (form < 0 || form > 2) throw std::invalid_argument("form: expected 0 (exact), 1 (karis) or 2 (hammon)");
    Column ic(wi, 3, "wi"), oc(wo, 3, "wo"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y");
    const py::ssize_t n = common_rows({&ic, &oc, &ax, &ay});
    return scalar_rows(n, [&](py::ssize_t i) {
        return mf::ggx_g2_over_4cos(ic.unit_vector(i), oc.unit_vector(i), ax.scalar(i), ay.scalar(i),
                                    static_cast<mf::GgxVisibility>(form));
    });
}

py::array_t<double> beckmann_sample_visible(const Float64Array& wo, const Float64Array& u1, const Float64Array& u2,
                                            const Float64Array& alpha_x, const Float64Array& alpha_y) {
    Column w(wo, 3, "wo"), c1(u1, 1, "u1"), c2(u2, 1, "u2"), ax(alpha_x, 1, "alpha_x"), ay(alpha_y, 1, "alpha_y");
    const py::ssize_t n = common_rows({&w, &c1, &c2, &ax, &ay});
    return vector_rows(n, [&](py::ssize_t i) {
        return mf::beckmann_sample_visible_h(w.unit_vector(i), c1.scalar(i), c2.scalar(i), ax.scalar(i), ay.scalar(i));
    });
}

py::array_t<double> hyp2f1(const Float64Array& a, const Float64Array& b, const Float64Array& c,
                           const Float64Array& z) {
    Column ac(a, 1, "a"), bc(b, 1, "b"), cc(c, 1, "c"), zc(z, 1, "z");
    const py::ssize_t n = common_rows({&ac, &bc, &cc, &zc});
    return scalar_rows(n, [&](py::ssize_t i) {
        return principled_brdf::special::hypergeometric_2f1(ac.scalar(i), bc.scalar(i), cc.scalar(i), zc.scalar(i));
    });
}

// the eight functions of one family member, as <prefix>_d, _pdf, _lambda, _g1, _g2_separable,
// _g2_height_correlated, _pdf_visible, _sample (all with the trailing shape argument)
template <class Distribution>
void def_family(py::module_& sub, const std::string& prefix, bool with_sampler = true) {
    const auto h = py::arg("h"), w = py::arg("w"), wi = py::arg("wi"), wo = py::arg("wo"), ax = py::arg("alpha_x"),
               ay = py::arg("alpha_y"), shape = py::arg("shape");
    sub.def((prefix + "_d").c_str(), &direction_alphas_shape<mf::family_d<Distribution>>, h, ax, ay, shape);
    sub.def((prefix + "_pdf").c_str(), &direction_alphas_shape<mf::family_pdf<Distribution>>, h, ax, ay, shape);
    sub.def((prefix + "_lambda").c_str(), &direction_alphas_shape<mf::family_lambda<Distribution>>, w, ax, ay, shape);
    sub.def((prefix + "_g1").c_str(), &direction_alphas_shape<mf::family_g1<Distribution>>, w, ax, ay, shape);
    sub.def((prefix + "_g2_separable").c_str(), &two_directions_alphas_shape<mf::family_g2_separable<Distribution>>,
            wi, wo, ax, ay, shape);
    sub.def((prefix + "_g2_height_correlated").c_str(),
            &two_directions_alphas_shape<mf::family_g2_height_correlated<Distribution>>, wi, wo, ax, ay, shape);
    sub.def((prefix + "_pdf_visible").c_str(), &two_directions_alphas_shape<mf::family_pdf_visible<Distribution>>, h,
            wo, ax, ay, shape);
    if (with_sampler)
        sub.def((prefix + "_sample").c_str(), &sample_alphas_shape<mf::family_sample<Distribution>>, py::arg("u1"),
                py::arg("u2"), ax, ay, shape);
}

}  // namespace

void bind_microfacet(py::module_& m) {
    py::module_ sub = m.def_submodule("microfacet", "Microfacet toolkit (docs/microfacet.md) over packed float64 rows.");
    const auto closed = py::arg("closed_forms");

    sub.def("gtr_d", &gtr_d, py::arg("cos_theta_h"), py::arg("alpha"), py::arg("gamma"), closed);
    sub.def("gtr_pdf", &gtr_pdf, py::arg("h"), py::arg("alpha"), py::arg("gamma"), closed);
    sub.def("gtr_sample", &gtr_sample, py::arg("u1"), py::arg("u2"), py::arg("alpha"), py::arg("gamma"), closed);

    sub.def("ggx_d", &direction_alphas<mf::ggx_d>, py::arg("h"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_pdf", &direction_alphas<mf::ggx_pdf_h>, py::arg("h"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_lambda", &direction_alphas<mf::ggx_lambda>, py::arg("w"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_g1", &direction_alphas<mf::ggx_g1>, py::arg("w"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_g2_separable", &two_directions_alphas<mf::ggx_g2_separable>, py::arg("wi"), py::arg("wo"),
            py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_g2_height_correlated", &two_directions_alphas<mf::ggx_g2_height_correlated>, py::arg("wi"),
            py::arg("wo"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_pdf_visible", &two_directions_alphas<mf::ggx_pdf_visible_h>, py::arg("h"), py::arg("wo"),
            py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_sample", &sample_alphas<mf::ggx_sample_h>, py::arg("u1"), py::arg("u2"), py::arg("alpha_x"),
            py::arg("alpha_y"));
    sub.def("ggx_sample_visible", &ggx_sample_visible, py::arg("wo"), py::arg("u1"), py::arg("u2"), py::arg("alpha_x"),
            py::arg("alpha_y"));

    sub.def("beckmann_d", &direction_alphas<mf::beckmann_d>, py::arg("h"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("beckmann_pdf", &direction_alphas<mf::beckmann_pdf_h>, py::arg("h"), py::arg("alpha_x"),
            py::arg("alpha_y"));
    sub.def("beckmann_lambda", &direction_alphas<mf::beckmann_lambda>, py::arg("w"), py::arg("alpha_x"),
            py::arg("alpha_y"));
    sub.def("beckmann_g1", &direction_alphas<mf::beckmann_g1>, py::arg("w"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("beckmann_sample", &sample_alphas<mf::beckmann_sample_h>, py::arg("u1"), py::arg("u2"), py::arg("alpha_x"),
            py::arg("alpha_y"));
    def_family<principled_brdf::f64::StudentT<double>>(sub, "student_t");
    def_family<principled_brdf::f64::ExponentialPower<double>>(sub, "exponential_power");
    def_family<principled_brdf::f64::BlinnPhong<double>>(sub, "blinn_phong");
    def_family<mf::BeckmannWalter>(sub, "beckmann_walter", false);
    sub.def("beckmann_g2_separable", &two_directions_alphas<mf::beckmann_g2_separable>, py::arg("wi"), py::arg("wo"),
            py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("beckmann_g2_height_correlated", &two_directions_alphas<mf::beckmann_g2_height_correlated>, py::arg("wi"),
            py::arg("wo"), py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("beckmann_pdf_visible", &two_directions_alphas<mf::beckmann_pdf_visible_h>, py::arg("h"), py::arg("wo"),
            py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("ggx_g2_over_4cos", &ggx_g2_over_4cos, py::arg("wi"), py::arg("wo"), py::arg("alpha_x"),
            py::arg("alpha_y"), py::arg("form"));
    sub.def("beckmann_sample_visible", &beckmann_sample_visible, py::arg("wo"), py::arg("u1"), py::arg("u2"),
            py::arg("alpha_x"), py::arg("alpha_y"));
    sub.def("fresnel_dielectric", &fresnel_dielectric, py::arg("cos_theta"), py::arg("eta"));
    sub.def("fresnel_conductor", &fresnel_conductor, py::arg("cos_theta"), py::arg("eta"), py::arg("k"));
    sub.def("refract", &refract, py::arg("w"), py::arg("eta"));
    sub.def("generalized_half_vector", &generalized_half_vector, py::arg("wi"), py::arg("wo"), py::arg("eta"));
    sub.def("refraction_jacobian", &refraction_jacobian, py::arg("wi"), py::arg("wo"), py::arg("eta"));
    sub.def("hyp2f1", &hyp2f1, py::arg("a"), py::arg("b"), py::arg("c"), py::arg("z"));
}

}  // namespace principled_brdf::bindings
