// The model (docs/model.md): the principled BRDF's parts over a number type,
// written once. Included inside a namespace that defines, for each number type
// F it instantiates the model with, the operations of model/scalar_ops.hpp
// (mul_add, reciprocal, select, min, max, any, all, log, sincos_turns, ...) and
// the macro PB_MODEL_INLINE; the kernels include it per instruction set,
// f64.hpp for double.
//
// Locals are not declared const: GCC 12 keeps a const aggregate that an inlined
// call constructs in place in memory (docs/model.md, "No const locals").
#include "vector.hpp"
#include "distributions.hpp"
#include "lobes.hpp"
#include "principled.hpp"
#include "energy.hpp"
#include "gradients.hpp"
