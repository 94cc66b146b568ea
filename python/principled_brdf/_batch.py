"""The batched float32 SIMD path: pb.eval, pb.eval_lobes, pb.pdf, pb.eval_pdf,
pb.sample, pb.random_uniforms, pb.cpu_info, and the kernel passes of the
derivatives, in the parameters and the directions, that ``_derivatives``
joins into pb.eval_grad and pb.eval_vjp.

Input handling, once per call:

* directions are ``(..., 3)`` (``layout="aos"``, the default) or ``(3, ...)``
  (``layout="soa"``); a float32 array is read in place, anything else (other
  dtypes) is converted once to float32 in its compact form (stride-0 axes
  not expanded);
* arguments that broadcast (by shape or as stride-0 views) are read in
  place by segments (_segments.py), never expanded to the call's shape;
* uniform material parameters are passed as numbers (no per-element loads);
  per-element ones as compact float32 arrays, cached on the Material.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple, overload

import numpy as np

from . import _core, _gradient, _models
from ._gradient import GRADIENT_NAMES
from ._model_checks import model_and_mode
from ._results import Gradient, Lobes, Sample, ValuePdf
from ._segments import choose_split, compact, leading_of, part, unexpanded
from ._validate import (
    DIRECTION_LENGTH_TOLERANCE,
    as_real_array,
    broadcast_leading,
    direction_error,
    element_name,
    flag,
    integer,
    layout as checked_layout,
    refuse_energy_compensation_derivative,
    require_float32,
    require_in_domain,
    sampler_index,
    seed_value,
    unit_length,
)
from .material import PARAMETERS, Material, require_material

if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any, Literal, SupportsIndex

    from numpy.typing import NDArray

    from ._typing import Float32Array, FloatArray, Layout, Mode, Model, RealArrayLike, SpecularSampler

__all__ = ["eval", "eval_lobes", "eval_pdf", "pdf", "sample", "random_uniforms", "cpu_info", "parameter_grad",
           "parameter_vjp", "direction_grad", "direction_vjp", "require_out_pair", "out_pair", "FLOAT32_LIMITS"]

_INTERLEAVED, _ROWS, _SINGLE = 0, 1, 2


def cpu_info() -> dict[str, Any]:
    """The instruction set in use (``PRINCIPLED_BRDF_ISA`` forces one), the
    available ones, SIMD width in floats and hardware threads."""
    return dict(_core.cpu_info())


def _threads(threads: SupportsIndex | None) -> int:
    if threads is None:
        return 0
    count = integer("threads", threads)
    if count < 1:
        raise ValueError(f"threads: expected at least 1, got {count}")
    if count > 2**31 - 1:
        raise ValueError(f"threads: expected at most 2**31 - 1, got {count}")
    return count


def _isa(isa: str | None) -> str:
    if isa is None:
        return ""
    available = _core.cpu_info()["available"]
    if isa not in available:
        raise ValueError(f"isa: {isa!r} is not available here (available: {', '.join(available)})")
    return isa


def _float32_input(name: str, value: object) -> tuple[Float32Array, FloatArray]:
    """(float32 aligned array, the values as given): a float32 array is read in
    place whatever its strides (the segments read its compact form), anything
    else converted once in its compact form (stride-0 axes not expanded),
    after a check that the values fit in float32, so that 1e300 is not
    reported as infinity."""
    if isinstance(value, np.ndarray) and value.dtype == np.float32:
        if value.flags.aligned:
            return value, value
        return np.require(value, np.float32, ["C_CONTIGUOUS", "ALIGNED"]), value
    given = as_real_array(name, value)
    require_float32(name, given)
    if given.ndim == 0:
        return np.ascontiguousarray(given, dtype=np.float32), given
    return np.broadcast_to(np.ascontiguousarray(unexpanded(given), dtype=np.float32), given.shape), given


class _Directions:
    """A direction argument as float32, with its leading shape and layout."""

    def __init__(self, name: str, value: object, layout: str) -> None:
        self.name = name
        self.array, self.given = _float32_input(name, value)
        array = self.array
        if layout == "aos":
            if array.ndim == 0 or array.shape[-1] != 3:
                raise ValueError(f"{name}: expected shape (..., 3) with layout='aos', got {array.shape}")
            self.leading = array.shape[:-1]
        else:
            if array.ndim == 0 or array.shape[0] != 3:
                raise ValueError(f"{name}: expected shape (3, ...) with layout='soa', got {array.shape}")
            self.leading = array.shape[1:]
        self.layout = layout

    def _own_index(self, element: int, leading: tuple[int, ...]) -> tuple[int, ...]:
        """The index into this argument's own leading shape of ``element`` of the broadcast ``leading``."""
        index = np.unravel_index(element, leading) if leading else ()
        trailing = index[len(index) - len(self.leading):]
        return tuple(int(i) if size > 1 else 0 for i, size in zip(trailing, self.leading))

    def error_at(self, element: int, leading: tuple[int, ...]) -> ValueError | None:
        """The ValueError for this argument at ``element``, or None when its vector passes."""
        own = self._own_index(element, leading)
        vector = self.array[own] if self.layout == "aos" else self.array[(slice(None),) + own]
        if unit_length(vector):
            return None
        flat_index = int(np.ravel_multi_index(own, self.leading)) if own else 0
        return direction_error(self.name, flat_index, self.leading, vector)


def _direction_error(element: int, leading: tuple[int, ...], *arguments: _Directions) -> ValueError:
    """The error for the element the kernel rejected: the first argument whose vector fails."""
    for argument in arguments:
        error = argument.error_at(element, leading)
        if error is not None:
            return error
    # The kernel and unit_length apply the same rule to the same floats.
    raise AssertionError(f"element {element} was rejected by the kernel and accepted by the check")


# The float32 kernels stay finite for parameters up to these bounds, all at
# once (f grows like base_color x roughness² through Fd90², and linearly in
# the other unbounded parameters; sample weights divide by small pdfs).
# Beyond them, use pb.reference.
FLOAT32_LIMITS = {"roughness": 1e4, "base_color": 1e20, "specular": 1e20, "sheen": 1e20, "clearcoat": 1e20}


def _require_float32_range(name: str, value: FloatArray) -> None:
    limit = FLOAT32_LIMITS.get(name)
    if limit is not None and value.size and value.max() > limit:
        i = int(np.flatnonzero(value.ravel() > limit)[0])
        raise ValueError(f"{element_name(name, i, value.shape)}: {float(value.ravel()[i])!r} is beyond what the "
                         f"float32 kernels represent (<= {limit:g}); pb.reference evaluates it in float64")


def _kernel_numbers(material: Material) -> list[float | tuple[float, ...] | None]:
    """Per parameter: its number (base_color's three) when uniform, else None;
    checked against FLOAT32_LIMITS and kept on the (immutable) material."""
    numbers = material._kernel_numbers
    if numbers is None:
        numbers = []
        for name, info in PARAMETERS.items():
            value = getattr(material, name)
            _require_float32_range(name, value)
            if value.shape != (() if info.slots == 1 else (3,)):
                numbers.append(None)
            else:
                numbers.append(tuple(float(v) for v in value) if info.slots == 3 else float(value))
        object.__setattr__(material, "_kernel_numbers", numbers)
    return numbers


def _parameter_views(material: Material, depth: int) -> list[float | tuple[float, ...] | Float32Array]:
    """One entry per parameter: a number (uniform), or the compact float32
    per-element values (compact(), cached on the material) padded to ``depth`` axes."""
    entries: list[float | tuple[float, ...] | Float32Array] = []
    for (name, info), number in zip(PARAMETERS.items(), _kernel_numbers(material)):
        entries.append(number if number is not None else
                       compact(material._float32_compact(name), depth, -1 if info.slots == 3 else None))
    return entries


_ABSENT = np.empty((0, 3), np.float32)  # the vector of an argument a call does not take


class _Segmented(NamedTuple):
    """A call's arguments as the segmented batch layer reads them."""

    vectors: list[tuple[Float32Array, int]]  # (array, layout code) of each direction argument
    params: list[float | tuple[float, ...] | Float32Array]
    segments: tuple[int, int, list[NDArray[np.int64] | None], list[bool]] | None  # _core's segments= (None: one run)


def _unsegmented(leading: tuple[int, ...], layout: str, directions: list[_Directions | None],
                 material: Material) -> _Segmented | None:
    """The arguments of a call that needs no segments (each one vector or
    number, or C-contiguous of the call's shape), or None: the common cases,
    without the segments' bookkeeping."""
    n = _size(leading)
    vectors: list[tuple[Float32Array, int]] = []
    for direction in directions:
        if direction is None:
            vectors.append((_ABSENT, 0))
        elif not direction.array.flags.c_contiguous:
            return None
        elif _size(direction.leading) == 1:  # () or (1, ...): one vector
            vectors.append((direction.array.reshape(3), _SINGLE))
        elif direction.leading == leading:
            vectors.append(_flat_vec3(direction.array, layout))
        else:
            return None
    params: list[float | tuple[float, ...] | Float32Array] = []
    for (name, info), number in zip(PARAMETERS.items(), _kernel_numbers(material)):
        if number is not None:
            params.append(number)
            continue
        values = material._float32_compact(name)
        if values.shape != (leading + (3,) if info.slots == 3 else leading):
            return None
        params.append(values.reshape((n, 3) if info.slots == 3 else (n,)))
    return _Segmented(vectors, params, None)


def _segmented(leading: tuple[int, ...], layout: str, directions: list[_Directions | None],
               material: Material) -> _Segmented:
    """Wi, wo and the third argument (cotangent or u; None entries for absent
    ones) and the material, read in place along the axes they broadcast on."""
    plain = _unsegmented(leading, layout, directions, material)
    if plain is not None:
        return plain
    depth = len(leading)
    axis = -1 if layout == "aos" else 0
    views = [None if d is None else compact(d.array, depth, axis) for d in directions]
    params = _parameter_views(material, depth)
    param_axes = [-1 if info.slots == 3 else None for info in PARAMETERS.values()]
    shapes = [leading_of(v, axis) for v in views if v is not None]
    shapes += [leading_of(p, a) for p, a in zip(params, param_axes) if isinstance(p, np.ndarray)]
    split = choose_split(leading, shapes)
    offsets: list[NDArray[np.int64] | None] = []
    vectors: list[tuple[Float32Array, int]] = []
    for view in views:
        if view is None:
            vectors.append((_ABSENT, 0))
            offsets.append(None)
            continue
        piece = part(view, leading, split, axis)
        if layout == "aos" or piece.single:  # one vector a segment: three floats in a row
            array = piece.array if layout == "aos" else np.ascontiguousarray(np.moveaxis(piece.array, 0, -1))
            vectors.append((array.reshape(-1, 3), _SINGLE if piece.single else _INTERLEAVED))
            offsets.append(None if piece.offsets is None else 3 * piece.offsets)
        else:
            vectors.append((piece.array.reshape(3, -1), _ROWS))
            offsets.append(piece.offsets)
    entries: list[float | tuple[float, ...] | Float32Array] = []
    single: list[bool] = []
    for value, param_axis in zip(params, param_axes):
        if not isinstance(value, np.ndarray):
            entries.append(value)
            single.append(False)
            offsets.append(None)
            continue
        piece = part(value, leading, split, param_axis)
        entries.append(piece.array.reshape(-1, 3) if param_axis == -1 else piece.array.reshape(-1))
        single.append(piece.single)
        offsets.append(None if piece.offsets is None else (3 if param_axis == -1 else 1) * piece.offsets)
    count = _size(leading[:split])
    return _Segmented(vectors, entries, (count, _size(leading[split:]), offsets, single))


def _output(out: object, shape: tuple[int, ...], name: str = "out") -> Float32Array:
    if out is None:
        return np.empty(shape, dtype=np.float32)
    if not isinstance(out, np.ndarray):
        raise TypeError(f"{name}: expected a numpy array, got {type(out).__name__}")
    if out.dtype != np.float32:
        raise TypeError(f"{name}: expected dtype float32, got {out.dtype}")
    if out.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {out.shape}")
    if not out.flags.c_contiguous or not out.flags.writeable:
        raise ValueError(f"{name}: expected a writeable C-contiguous array")
    if not out.flags.aligned:
        raise ValueError(f"{name}: array data is not aligned to 4 bytes (the kernels write whole floats)")
    return out


def _output_name(outputs: list[Float32Array], k: int) -> str:
    """How an error names output k: ``out``, or ``out[k]`` of several."""
    return "out" if len(outputs) == 1 else f"out[{k}]"


def _require_no_partial_overlap(out: NDArray[Any], inputs: dict[str, NDArray[Any] | None], name: str = "out") -> None:
    """An ``out=`` that is exactly an input computes in place; one that partly overlaps
    an input would read elements it has already overwritten: a ValueError."""
    for input_name, array in inputs.items():
        # Both are dense blocks (C-contiguous), so sharing bounds is sharing memory.
        if array is None or not np.may_share_memory(out, array):
            continue
        same = (out.__array_interface__["data"][0] == array.__array_interface__["data"][0]
                and out.shape == array.shape and out.strides == array.strides)
        if not same:
            raise ValueError(f"{name}: overlaps {input_name} without being the same array "
                             "(only an exact alias computes in place)")


def _as_array(value: object) -> NDArray[Any] | None:
    return value if isinstance(value, np.ndarray) else None


def _size(leading: tuple[int, ...]) -> int:
    return math.prod(leading)


def _vec3_shape(leading: tuple[int, ...], layout: str) -> tuple[int, ...]:
    return leading + (3,) if layout == "aos" else (3,) + leading


def _flat_vec3(array: Float32Array, layout: str) -> tuple[Float32Array, int]:
    n = _size(array.shape[:-1] if layout == "aos" else array.shape[1:])
    return (array.reshape(n, 3), _INTERLEAVED) if layout == "aos" else (array.reshape(3, n), _ROWS)


def _evaluate(material: Material, wi: object, wo: object, model_id: int, cosine: bool, layout: Layout,
              threads: SupportsIndex | None, check: bool, isa: str | None,
              outputs_for_shape: Callable[[tuple[int, ...], str], list[Float32Array]], pdf_sampler: int | None = None,
              gradient: bool = False, energy_compensation: bool = False, columns: list[int] | None = None,
              cotangent: Float32Array | None = None, directions: bool = False, mode_id: int = 0) -> list[Float32Array]:
    """eval / eval_lobes / pdf / eval_grad / eval_vjp: validated arguments in, outputs written.
    ``columns``: the slots a derivative is taken by (None: all). ``cotangent``
    (float32, f's layout, broadcasting to the call's shape): the output is
    the vector-Jacobian product. ``directions``: the derivatives in the six
    direction components instead of the slots."""
    vjp = cotangent is not None
    require_material("material", material)
    if gradient or vjp or directions:
        refuse_energy_compensation_derivative(energy_compensation, _core.MODEL_NAMES[model_id])
    energy_compensation = flag("energy_compensation", energy_compensation)
    layout = checked_layout(layout)
    thread_count = _threads(threads)
    isa_name = _isa(isa)
    cosine, check = flag("cosine", cosine), flag("check", check)
    wi_dirs = _Directions("wi", wi, layout)
    wo_dirs = _Directions("wo", wo, layout)
    leading = broadcast_leading(wi=wi_dirs.leading, wo=wo_dirs.leading, material=material.shape)
    outputs = outputs_for_shape(leading, layout)
    # The check rides along with the evaluation (docs/bad-input.md): on a bad
    # direction the call raises, and an out= buffer may hold partial results.
    tolerance = DIRECTION_LENGTH_TOLERANCE if check else 0.0
    out_layout = _INTERLEAVED if layout == "aos" else _ROWS
    # one options object a call, made once for all its segments
    options: _core.EvalOptions | _core.PdfOptions
    if pdf_sampler is None:
        options = _core.EvalOptions(model=model_id, cosine=cosine, energy_compensation=energy_compensation,
                                    mode=mode_id, check_tolerance=tolerance, threads=thread_count, isa=isa_name)
    else:
        options = _core.PdfOptions(model=model_id, sampler=pdf_sampler, cosine=cosine,
                                   energy_compensation=energy_compensation, mode=mode_id, check_tolerance=tolerance,
                                   threads=thread_count, isa=isa_name)

    third = None
    if cotangent is not None:
        third = _Directions("cotangent", cotangent, layout)
        call_shape = _vec3_shape(leading, layout)
        try:
            np.broadcast_to(cotangent, call_shape)
        except ValueError:
            raise ValueError(f"cotangent: shape {np.shape(cotangent)} does not broadcast to the call's {call_shape}") from None
    call = _segmented(leading, layout, [wi_dirs, wo_dirs, third], material)
    (wi_flat, wi_code), (wo_flat, wo_code), (cotangent_flat, cotangent_code) = call.vectors
    params, segments, n = call.params, call.segments, _size(leading)
    for k, output in enumerate(outputs):
        _require_no_partial_overlap(output, {"wi": wi_flat, "wo": wo_flat}, _output_name(outputs, k))
    if isinstance(options, _core.PdfOptions):
        f = _flat_vec3(outputs[1], layout)[0] if len(outputs) == 2 else None  # eval_pdf: f in the same pass
        bad = _core.batch_pdf(wi=wi_flat, wi_layout=wi_code, wo=wo_flat, wo_layout=wo_code, params=params,
                              pdf=outputs[0].reshape(n), out=f, out_layout=out_layout, n=n, options=options,
                              segments=segments)
    elif directions and vjp:
        (product,) = outputs
        bad = _core.batch_eval_direction_vjp(
            wi=wi_flat, wi_layout=wi_code, wo=wo_flat, wo_layout=wo_code, params=params,
            cotangent=cotangent_flat, cotangent_layout=cotangent_code,
            vjp=product.reshape((n, 6) if layout == "aos" else (6, n)), out_layout=out_layout, n=n,
            options=options, segments=segments)
    elif directions:
        value, jacobian = outputs
        bad = _core.batch_eval_direction_grad(
            wi=wi_flat, wi_layout=wi_code, wo=wo_flat, wo_layout=wo_code, params=params,
            out=_flat_vec3(value, layout)[0], jacobian=jacobian.reshape((n, 3, 6) if layout == "aos" else (3, 6, n)),
            out_layout=out_layout, n=n, options=options, segments=segments)
    elif gradient:
        width = len(GRADIENT_NAMES) if columns is None else len(columns)
        value, jacobian = outputs
        bad = _core.batch_eval_grad(
            wi=wi_flat, wi_layout=wi_code, wo=wo_flat, wo_layout=wo_code, params=params,
            out=_flat_vec3(value, layout)[0],
            jacobian=jacobian.reshape((n, 3, width) if layout == "aos" else (3, width, n)),
            out_layout=out_layout, n=n, options=options, columns=columns, segments=segments)
    elif vjp:
        width = len(GRADIENT_NAMES) if columns is None else len(columns)
        (product,) = outputs
        bad = _core.batch_eval_vjp(
            wi=wi_flat, wi_layout=wi_code, wo=wo_flat, wo_layout=wo_code, params=params,
            cotangent=cotangent_flat, cotangent_layout=cotangent_code,
            vjp=product.reshape((n, width) if layout == "aos" else (width, n)),
            out_layout=out_layout, n=n, options=options, columns=columns, segments=segments)
    else:
        bad = _core.batch_eval(
            wi=wi_flat, wi_layout=wi_code, wo=wo_flat, wo_layout=wo_code, params=params,
            outputs=[_flat_vec3(o, layout)[0] for o in outputs], lobes=len(outputs) == len(_models.LOBE_NAMES),
            out_layout=out_layout, n=n, options=options, segments=segments)
    if bad >= 0:
        raise _direction_error(bad, leading, wi_dirs, wo_dirs)
    return outputs


def eval(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model = "disney2014",
         cosine: bool = False, layout: Layout = "aos", threads: SupportsIndex | None = None,
         out: Float32Array | None = None, check: bool = True, isa: str | None = None,
         energy_compensation: bool = False, mode: Mode = "radiance") -> Float32Array:
    """f(wi, wo) in 1/sr as float32, by the SIMD kernel (docs/model.md, "The model").

    ``wi``, ``wo``: unit directions, ``(..., 3)`` or with ``layout="soa"``
    ``(3, ...)``; leading shapes broadcast with each other and with the
    material's. Returns ``(..., 3)`` (``(3, ...)`` for ``"soa"``), written into
    ``out`` if given (float32, C-contiguous, exact shape). ``cosine`` multiplies
    by cos θl. ``threads``: default all cores; results are bit-identical for
    every thread count. ``check=False`` skips the direction checks for speed:
    a non-unit direction is then used as given and a non-finite one gives 0. ``isa``
    picks one of ``cpu_info()["available"]`` (for tests and benchmarks).
    ``energy_compensation=True`` adds the primary specular lobe's multiple
    scattering (Kulla & Conty 2017; docs/energy-compensation.md).
    ``model="disney2015"``: the 2015 BSDF over the whole sphere
    (docs/model-2015.md), ``cosine`` then multiplies by ``|cos θl|``, and ``mode``
    (``"radiance"`` or ``"importance"``) says which way light flows through
    the interface (the transmission differs by η_t²).
    """
    model_id, mode_id = model_and_mode(material, model, mode, energy_compensation)
    (f,) = _evaluate(material, wi, wo, model_id, cosine, layout, threads, check, isa,
                     lambda leading, layout: [_output(out, _vec3_shape(leading, layout))],
                     energy_compensation=energy_compensation, mode_id=mode_id)
    return f


def eval_lobes(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model = "disney2014",
               cosine: bool = False, layout: Layout = "aos", threads: SupportsIndex | None = None, check: bool = True,
               isa: str | None = None, energy_compensation: bool = False, mode: Mode = "radiance") -> Lobes:
    """The lobes (diffuse, sheen, specular, clearcoat, multiple_scattering,
    transmission, diffuse_transmission) as a :class:`Lobes` of float32 arrays, each shaped like
    :func:`eval`'s result; multiple_scattering is 0 unless
    ``energy_compensation``, transmission 0 but for the 2015 models,
    diffuse_transmission 0 but for ``disney2015_thin``."""
    model_id, mode_id = model_and_mode(material, model, mode, energy_compensation)
    outputs = _evaluate(material, wi, wo, model_id, cosine, layout, threads, check, isa,
                        lambda leading, layout: [np.empty(_vec3_shape(leading, layout), np.float32) for _ in _models.LOBE_NAMES],
                        energy_compensation=energy_compensation, mode_id=mode_id)
    return Lobes(*outputs)


def require_out_pair(out: object, second: str) -> None:
    """``out=`` of a call with two results, f and ``second``: None or a tuple of two arrays."""
    if out is not None and not (isinstance(out, tuple) and len(out) == 2):
        raise TypeError(f"out: expected a tuple (value, {second}) of float32 arrays")


def out_pair(out: tuple[object, object] | None, value_shape: tuple[int, ...], second_shape: tuple[int, ...],
             second: str) -> tuple[Float32Array, Float32Array]:
    """The two result arrays: fresh, or ``out``'s checked (shapes, dtype, no overlap)."""
    if out is not None:
        for i, array in enumerate(out):
            if array is None:
                raise TypeError(f"out[{i}]: expected a float32 array, got None (out= takes both arrays)")
    value = _output(None if out is None else out[0], value_shape, "out[0]")
    other = _output(None if out is None else out[1], second_shape, "out[1]")
    if out is not None and np.may_share_memory(value, other):
        raise ValueError(f"out: the value and {second} arrays overlap")
    return value, other


def _jacobian_shape(leading: tuple[int, ...], layout: str, width: int) -> tuple[int, ...]:
    return leading + (3, width) if layout == "aos" else (3, width) + leading


def parameter_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *,
                   wrt: str | list[str] | tuple[str, ...] | None = None, model: Model = "disney2014",
                   cosine: bool = False, layout: Layout = "aos", threads: SupportsIndex | None = None,
                   out: tuple[Float32Array, Float32Array] | None = None, check: bool = True,
                   isa: str | None = None, energy_compensation: bool = False, mode: Mode = "radiance") -> Gradient:
    """pb.eval_grad in the parameters only (its arguments, checked as it checks them)."""
    model_id, mode_id = model_and_mode(material, model, mode, energy_compensation)
    names = _gradient.gradient_names(model)
    wanted = _gradient.columns(wrt, names=names)
    full = len(wanted) == len(GRADIENT_NAMES) and names == GRADIENT_NAMES  # (the 2015 models name their columns)
    require_out_pair(out, "jacobian")

    def outputs(leading: tuple[int, ...], layout: str) -> list[Float32Array]:
        value, jacobian = out_pair(out, _vec3_shape(leading, layout), _jacobian_shape(leading, layout, len(wanted)),
                                   "jacobian")
        return [value, jacobian]

    # the kernel computes and writes the wanted columns only
    value, jacobian = _evaluate(material, wi, wo, model_id, cosine, layout, threads, check, isa, outputs,
                                gradient=True, energy_compensation=energy_compensation,
                                columns=None if full else wanted, mode_id=mode_id)
    return Gradient(value, jacobian, tuple(names[k] for k in wanted))


def parameter_vjp(material: Material, wi: object, wo: object, cotangent: Float32Array, *, columns: list[int],
                  model_id: int, mode_id: int, cosine: bool, layout: Layout, threads: SupportsIndex | None,
                  check: bool, isa: str | None) -> Float32Array:
    """``Σ_c g_c ∂f_c/∂p`` per element for the slots ``columns``: ``(..., P)`` at the call's
    broadcast shape (``(P, ...)`` for ``layout="soa"``), for a float32 ``cotangent`` in f's layout."""
    soa = layout == "soa"

    def outputs(leading: tuple[int, ...], layout: str) -> list[Float32Array]:
        return [np.empty(leading + (len(columns),) if not soa else (len(columns),) + leading, np.float32)]

    (product,) = _evaluate(material, wi, wo, model_id, cosine, layout, threads, check, isa, outputs,
                           energy_compensation=False, columns=columns, cotangent=cotangent, mode_id=mode_id)
    return product


# The six direction components the derivatives in the directions are taken by: wi's, then wo's.
DIRECTION_COMPONENTS = 6


def direction_grad(material: Material, wi: object, wo: object, *, model_id: int, mode_id: int, cosine: bool,
                   layout: Layout, threads: SupportsIndex | None, check: bool,
                   isa: str | None, energy_compensation: bool = False) -> tuple[Float32Array, Float32Array]:
    """f and its derivatives in the six direction components, ``(..., 3)`` and
    ``(..., 3, 6)`` (``(3, ...)`` and ``(3, 6, ...)`` for ``layout="soa"``), by the model's
    forward mode over double batches (``model/direction_gradient.hpp``)."""

    def outputs(leading: tuple[int, ...], layout: str) -> list[Float32Array]:
        return [np.empty(_vec3_shape(leading, layout), np.float32),
                np.empty(_jacobian_shape(leading, layout, DIRECTION_COMPONENTS), np.float32)]

    value, jacobian = _evaluate(material, wi, wo, model_id, cosine, layout, threads, check, isa, outputs,
                                directions=True, mode_id=mode_id, energy_compensation=energy_compensation)
    return value, jacobian


def direction_vjp(material: Material, wi: object, wo: object, cotangent: Float32Array, *, model_id: int,
                  mode_id: int, cosine: bool, threads: SupportsIndex | None, isa: str | None) -> Float32Array:
    """``Σ_c g_c ∂f_c/∂w`` per element in the six direction components, ``(..., 6)``, for
    ``(..., 3)`` arguments and a float32 ``cotangent`` broadcasting with them."""

    def outputs(leading: tuple[int, ...], layout: str) -> list[Float32Array]:
        return [np.empty(leading + (DIRECTION_COMPONENTS,), np.float32)]

    (product,) = _evaluate(material, wi, wo, model_id, cosine, "aos", threads, True, isa, outputs,
                           cotangent=cotangent, directions=True, mode_id=mode_id)
    return product


def pdf(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model = "disney2014",
        specular_sampler: SpecularSampler = "visible", layout: Layout = "aos", threads: SupportsIndex | None = None,
        check: bool = True, isa: str | None = None, energy_compensation: bool = False) -> Float32Array:
    """The density (solid angle) with which :func:`sample` draws ``wi`` given ``wo``:
    the lobe mixture of docs/sampling.md for ``model``, float32 ``(...)``.

    The 2012 and 2014 models share one density, 0 when either direction is at
    or below the horizon, unless ``energy_compensation``, whose lobe's mixture
    weight reads the model's tables. The 2015 models (``"disney2015"``,
    ``"disney2015_thin"``) each have their own, over the whole sphere: the
    reflecting lobes where ``wi`` lies on the viewer's side, the transmission
    where it lies on the other (docs/sampling.md, "The 2015 solid" and
    "The 2015 thin sheet")."""
    model_id = model_and_mode(material, model, energy_compensation=energy_compensation)[0]
    by_model = energy_compensation or _models.is_whole_sphere(model)  # else the pdf is the 2014 model's
    (density,) = _evaluate(material, wi, wo, model_id if by_model else 0, False, layout, threads, check, isa,
                           lambda leading, layout: [np.empty(leading, np.float32)],
                           pdf_sampler=sampler_index(specular_sampler), energy_compensation=energy_compensation)
    return density


def eval_pdf(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model = "disney2014",
             cosine: bool = False, specular_sampler: SpecularSampler = "visible", layout: Layout = "aos",
             threads: SupportsIndex | None = None, out: tuple[Float32Array, Float32Array] | None = None,
             check: bool = True, isa: str | None = None, energy_compensation: bool = False,
             mode: Mode = "radiance") -> ValuePdf:
    """f and the sampling pdf of (wi, wo) in one kernel pass (what multiple importance
    sampling needs): ``value`` as :func:`eval` returns it, ``pdf`` as :func:`pdf` does.
    ``out=(value, pdf)`` writes into preallocated float32 arrays of those shapes."""
    require_out_pair(out, "pdf")

    def outputs(leading: tuple[int, ...], layout: str) -> list[Float32Array]:
        value, density = out_pair(out, _vec3_shape(leading, layout), leading, "pdf")
        return [density, value]

    model_id, mode_id = model_and_mode(material, model, mode, energy_compensation)
    density, value = _evaluate(material, wi, wo, model_id, cosine, layout, threads, check, isa, outputs,
                               pdf_sampler=sampler_index(specular_sampler), energy_compensation=energy_compensation,
                               mode_id=mode_id)
    return ValuePdf(value, density)


def random_uniforms(seed: SupportsIndex, n: SupportsIndex, first: SupportsIndex = 0) -> Float32Array:
    """The ``(n, 3)`` uniforms :func:`sample` draws for elements ``first .. first + n - 1``
    when given ``seed`` and no ``u`` (a counter-based generator keyed by seed and index)."""
    count, start = integer("n", n), integer("first", first)
    if count < 0 or start < 0:
        raise ValueError(f"n, first: expected non-negative integers, got {count}, {start}")
    if start + count > 2**63 - 1:
        raise ValueError(f"first + n: expected at most 2**63 - 1 (the generator's index range), got {start + count}")
    if 3 * count > np.iinfo(np.intp).max // 4:
        raise ValueError(f"n: {count} rows of three float32 do not fit in memory")
    return _core.counter_uniforms(seed_value(seed), start, count)


def _fresh_seed() -> int:
    """A seed from the operating system's randomness, as numpy's default_rng() takes one."""
    return int(np.random.SeedSequence().generate_state(1, np.uint64)[0])


@overload
def sample(material: Material, wo: RealArrayLike, *, u: RealArrayLike | None = None,
           seed: SupportsIndex | None = None, n: SupportsIndex | None = None, model: Model = "disney2014",
           specular_sampler: SpecularSampler = "visible", layout: Layout = "aos", threads: SupportsIndex | None = None,
           check: bool = True, isa: str | None = None, with_lobes: Literal[False] = False,
           energy_compensation: bool = False, mode: Mode = "radiance") -> Sample: ...
@overload
def sample(material: Material, wo: RealArrayLike, *, u: RealArrayLike | None = None,
           seed: SupportsIndex | None = None, n: SupportsIndex | None = None, model: Model = "disney2014",
           specular_sampler: SpecularSampler = "visible", layout: Layout = "aos", threads: SupportsIndex | None = None,
           check: bool = True, isa: str | None = None, with_lobes: Literal[True],
           energy_compensation: bool = False, mode: Mode = "radiance") -> tuple[Sample, Lobes]: ...
@overload
def sample(material: Material, wo: RealArrayLike, *, u: RealArrayLike | None = None,
           seed: SupportsIndex | None = None, n: SupportsIndex | None = None, model: Model = "disney2014",
           specular_sampler: SpecularSampler = "visible", layout: Layout = "aos", threads: SupportsIndex | None = None,
           check: bool = True, isa: str | None = None, with_lobes: bool = False,
           energy_compensation: bool = False, mode: Mode = "radiance") -> Sample | tuple[Sample, Lobes]: ...
def sample(material: Material, wo: RealArrayLike, *, u: RealArrayLike | None = None,
           seed: SupportsIndex | None = None, n: SupportsIndex | None = None, model: Model = "disney2014",
           specular_sampler: SpecularSampler = "visible", layout: Layout = "aos", threads: SupportsIndex | None = None,
           check: bool = True, isa: str | None = None, with_lobes: bool = False,
           energy_compensation: bool = False, mode: Mode = "radiance") -> Sample | tuple[Sample, Lobes]:
    """Importance-sample ``wi`` for each ``wo`` (docs/sampling.md).

    ``u``: three uniforms in [0, 1] per element, ``(..., 3)`` (``(3, ...)`` for
    ``layout="soa"``), broadcast with ``wo`` and the material; without it they
    come from a counter-based generator keyed by ``(seed, element index)``
    (C order over the broadcast leading shape), independent of ``threads``:
    an integer ``seed`` reproduces them, ``seed=None`` (the default) takes a
    fresh one from the operating system, as ``np.random.default_rng()`` does.
    ``n``: that many samples of every element, the result's leading shape
    ``(n,) + `` the broadcast one (``pb.sample(m, wo, n=1 << 20)`` for one
    ``wo`` of shape ``(3,)``); not with ``u``.
    Returns a :class:`Sample` of float32 ``wi``, ``pdf``, ``weight`` and int32 ``lobe``;
    with ``with_lobes=True``, ``(Sample, Lobes)``: each lobe's share of the weight,
    ``f_k(wi, wo) cos θl / pdf``, from the same pass (they sum to ``weight``).
    ``energy_compensation=True``: f includes the multiple-scattering lobe, drawn
    by the cosine lobe (its weight joins that lobe's chance, ``lobe`` 0).
    ``model="disney2015"`` or ``"disney2015_thin"``: ``wi`` anywhere on the
    sphere, ``lobe`` 3 for the transmission (4: the thin sheet's diffuse
    transmission); weight ``f |cos θl| / pdf`` with ``f`` in ``mode``. At the
    solid's interface a draw splits at its microfacet: under total internal
    reflection there it reflects (``lobe`` 1). A refraction at a microfacet
    facing away from ``wo``, which only ``specular_sampler="distribution"``
    draws, is no sample (``wi`` 0, pdf and weight 0); a draw that lands on the
    wrong side of the surface for its lobe keeps its ``wi`` with pdf and
    weight 0 (docs/sampling.md).
    """
    model_id, mode_id = model_and_mode(material, model, mode, energy_compensation)
    sampler = sampler_index(specular_sampler)
    layout = checked_layout(layout)
    thread_count = _threads(threads)
    isa_name = _isa(isa)
    seed = _fresh_seed() if seed is None else seed_value(seed)
    check, with_lobes = flag("check", check), flag("with_lobes", with_lobes)
    energy_compensation = flag("energy_compensation", energy_compensation)
    wo_dirs = _Directions("wo", wo, layout)
    shapes = dict(wo=wo_dirs.leading, material=material.shape)
    uniforms = None
    if u is not None:
        uniforms = _Directions("u", u, layout)  # shape and dtype handling of a 3-vector argument
        require_in_domain("u", uniforms.given, 0.0, 1.0)  # the values as given, as pb.reference checks them
        shapes["u"] = uniforms.leading
    leading = broadcast_leading(**shapes)
    if n is not None:
        if u is not None:
            raise ValueError("n: not with u (the uniforms give the number of samples)")
        count = integer("n", n)
        if count < 0:
            raise ValueError(f"n: expected a count >= 0, got {count}")
        leading = (count,) + leading  # n samples of every element
    n = _size(leading)
    wi_out = np.empty(_vec3_shape(leading, layout), np.float32)
    weight_out = np.empty_like(wi_out)
    pdf_out = np.empty(leading, np.float32)
    lobe_out = np.empty(leading, np.int32)
    shares = [np.empty_like(wi_out) for _ in _models.LOBE_NAMES] if with_lobes else None
    call = _segmented(leading, layout, [None, wo_dirs, uniforms], material)
    (wo_flat, wo_code), (u_flat, u_code) = call.vectors[1:]
    options = _core.SampleOptions(model=model_id, sampler=sampler, energy_compensation=energy_compensation, mode=mode_id,
                                  seed=seed,
                                  check_tolerance=DIRECTION_LENGTH_TOLERANCE if check else 0.0,
                                  threads=thread_count, isa=isa_name)
    bad = _core.batch_sample(
        wo=wo_flat, wo_layout=wo_code, u=None if uniforms is None else u_flat, u_layout=u_code, params=call.params,
        wi=_flat_vec3(wi_out, layout)[0], weight=_flat_vec3(weight_out, layout)[0], pdf=pdf_out.reshape(n),
        lobe=lobe_out.reshape(n), lobe_weights=None if shares is None else [_flat_vec3(s, layout)[0] for s in shares],
        out_layout=_INTERLEAVED if layout == "aos" else _ROWS, n=n, options=options, segments=call.segments,
    )
    if bad >= 0:
        raise _direction_error(bad, leading, wo_dirs)
    drawn = Sample(wi_out, pdf_out, weight_out, lobe_out)
    return (drawn, Lobes(*shares)) if shares is not None else drawn  # shares is None unless with_lobes
