// The microfacet family (model/distribution_family.hpp) instantiated for
// double in principled_brdf::f64, beside the model of model/f64.hpp, with the
// double-only operations it needs: Smith's Λ of the Student-t and
// exponential-power slopes (smith_lambda.hpp), the inverse regularised
// incomplete gamma function and ln Γ (special_functions.hpp). Only the
// float64 toolkit (microfacet_family.hpp) uses it.
#pragma once

#include "principled_brdf/model/f64.hpp"
#include "principled_brdf/smith_lambda.hpp"
#include "principled_brdf/special_functions.hpp"

namespace principled_brdf::f64 {

inline double student_t_lambda_of(double nu, double a) { return special::student_t_lambda(nu, a); }
inline double exponential_power_lambda_of(double p, double a) { return special::exponential_power_lambda(p, a); }
inline double inverse_regularized_gamma_of(double s, double u, double u_complement) {
    return special::inverse_regularized_gamma(s, u, u_complement);
}
inline double log_gamma(double x) { return std::lgamma(x); }

#define PB_MODEL_INLINE inline
#include "distribution_family.hpp"
#undef PB_MODEL_INLINE

}  // namespace principled_brdf::f64
