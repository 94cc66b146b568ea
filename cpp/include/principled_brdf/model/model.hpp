// The model (docs/model.md): the principled BRDF's parts over a number type,
// written once. Included inside a namespace that defines, for each number type
// F it instantiates the model with, the operations of model/scalar_ops.hpp
// (mul_add, reciprocal, select, min, max, any, all, log, sincos_turns, ...) and
// the macro PB_MODEL_INLINE; the kernels include it per instruction set,
// f64.hpp for double.
//
// Locals are not declared const: GCC 12 keeps a const aggregate that an inlined
// call constructs in place in memory (docs/model.md, "No const locals").
//
// One namespace a translation unit. The model's files are `#pragma once`,
// which holds per translation unit, not per namespace: a second inclusion
// under another namespace (f64.hpp and kernel.hpp in one file, or two
// kernels) would find them already seen and leave that namespace without the
// model. This guard makes it a compile error instead.
#ifdef PRINCIPLED_BRDF_MODEL_INCLUDED
#error "principled_brdf: the model (model/model.hpp) is included a second time in this translation unit; it can live in one namespace only, so f64.hpp and each kernel_<isa>.cpp need translation units of their own"
#endif
#define PRINCIPLED_BRDF_MODEL_INCLUDED

#include "vector.hpp"
#include "distributions.hpp"
#include "dielectric.hpp"
#include "dielectric_energy.hpp"
#include "lobes.hpp"
#include "principled.hpp"
#include "bsdf2015.hpp"
#include "energy.hpp"
#include "gradients.hpp"
#include "dual.hpp"
#include "direction_gradient.hpp"
#include "bsdf2015_gradient.hpp"
