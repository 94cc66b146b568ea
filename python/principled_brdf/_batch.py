"""The batched float32 SIMD path: pb.eval, pb.eval_lobes, pb.cpu_info.

Input handling, once per call:

* directions are ``(..., 3)`` (``layout="aos"``, the default) or ``(3, ...)``
  (``layout="soa"``); a float32 C-contiguous array is read in place, anything
  else (other dtypes, strides) is converted once to a float32 copy;
* a direction whose leading shape is ``()`` is one vector for every element
  (read once, never copied); other broadcasts are materialised;
* uniform material parameters are passed as numbers (no per-element loads);
  per-element ones as float32 arrays, cached on the Material.
"""

from __future__ import annotations

import operator

import numpy as np

from . import _core
from ._validate import (
    DIRECTION_LENGTH_TOLERANCE,
    as_real_array,
    broadcast_leading,
    element_name,
    model_index,
    require_in_domain,
)
from .material import PARAMETERS, Material
from .reference import Lobes, Sample

__all__ = ["eval", "eval_lobes", "pdf", "sample", "random_uniforms", "Sample", "cpu_info"]

_INTERLEAVED, _ROWS, _SINGLE = 0, 1, 2
_LAYOUTS = ("aos", "soa")


_SPECULAR_SAMPLERS = {"visible": 0, "distribution": 1}


def cpu_info() -> dict:
    """The instruction set in use (``PRINCIPLED_BRDF_ISA`` forces one), the
    available ones, SIMD width in floats and hardware threads."""
    return dict(_core.cpu_info())


def _layout(layout) -> str:
    if layout not in _LAYOUTS:
        raise ValueError(f"layout: expected 'aos' for (..., 3) or 'soa' for (3, ...), got {layout!r}")
    return layout


def _threads(threads) -> int:
    if threads is None:
        return 0
    try:
        count = operator.index(threads)
    except TypeError:
        raise TypeError(f"threads: expected an integer, got {type(threads).__name__}") from None
    if count < 1:
        raise ValueError(f"threads: expected at least 1, got {count}")
    return count


def _specular_sampler(name) -> int:
    if name not in _SPECULAR_SAMPLERS:
        raise ValueError(f"specular_sampler: expected one of {sorted(_SPECULAR_SAMPLERS)}, got {name!r}")
    return _SPECULAR_SAMPLERS[name]


def _seed(seed) -> int:
    try:
        value = operator.index(seed)
    except TypeError:
        raise TypeError(f"seed: expected an integer, got {type(seed).__name__}") from None
    if not 0 <= value < 2**64:
        raise ValueError(f"seed: expected 0 <= seed < 2**64, got {value}")
    return value


def _isa(isa) -> str:
    if isa is None:
        return ""
    available = _core.cpu_info()["available"]
    if isa not in available:
        raise ValueError(f"isa: {isa!r} is not available here (available: {', '.join(available)})")
    return isa


class _Directions:
    """A direction argument as float32, with its leading shape and layout."""

    def __init__(self, name: str, value, layout: str):
        self.name = name
        if isinstance(value, np.ndarray) and value.dtype == np.float32:
            array = value
        else:
            array = as_real_array(name, value).astype(np.float32)
        if layout == "aos":
            if array.ndim == 0 or array.shape[-1] != 3:
                raise ValueError(f"{name}: expected shape (..., 3) with layout='aos', got {array.shape}")
            self.leading = array.shape[:-1]
        else:
            if array.ndim == 0 or array.shape[0] != 3:
                raise ValueError(f"{name}: expected shape (3, ...) with layout='soa', got {array.shape}")
            self.leading = array.shape[1:]
        self.layout = layout
        self.array = np.ascontiguousarray(array)  # no copy when already C-contiguous

    def flat(self, leading: tuple):
        """(array, layout code) with ``leading`` elements; broadcasts if needed."""
        array = self.array
        if self.leading == ():
            return array.reshape(3), _SINGLE
        if self.leading != leading:
            target = leading + (3,) if self.layout == "aos" else (3,) + leading
            array = np.ascontiguousarray(np.broadcast_to(array, target))
        n = int(np.prod(leading, dtype=np.int64))
        return (array.reshape(n, 3), _INTERLEAVED) if self.layout == "aos" else (array.reshape(3, n), _ROWS)

    def check(self, threads: int) -> None:
        """SPEC §7: every direction finite and of unit length within tolerance."""
        flat, code = self.flat(self.leading)
        n = 1 if code == _SINGLE else int(np.prod(self.leading, dtype=np.int64))
        bad = _core.check_directions(flat, code, n, DIRECTION_LENGTH_TOLERANCE, threads)
        if bad < 0:
            return
        vector = flat[bad] if code == _INTERLEAVED else flat[:, bad] if code == _ROWS else flat
        where = element_name(self.name, bad, self.leading)
        if not np.all(np.isfinite(vector)):
            raise ValueError(f"{where}: {vector.tolist()} is not a finite vector")
        length = float(np.sqrt(np.sum(vector.astype(np.float64) ** 2)))
        raise ValueError(f"{where}: length {length:.6g} is not 1 (within {DIRECTION_LENGTH_TOLERANCE:g})")


# The float32 kernels stay finite for parameters up to these bounds, all at
# once (f grows like base_color x roughness² through Fd90², and linearly in
# the other unbounded parameters; sample weights divide by small pdfs).
# Beyond them, use pb.reference.
FLOAT32_LIMITS = {"roughness": 1e4, "base_color": 1e20, "specular": 1e20, "sheen": 1e20, "clearcoat": 1e20}


def _require_float32_range(name: str, value: np.ndarray) -> None:
    limit = FLOAT32_LIMITS.get(name)
    if limit is not None and value.size and value.max() > limit:
        i = int(np.flatnonzero(value.ravel() > limit)[0])
        raise ValueError(f"{element_name(name, i, value.shape)}: {float(value.ravel()[i])!r} is beyond what the "
                         f"float32 kernels represent (<= {limit:g}); pb.reference evaluates it in float64")


def _params(material: Material, leading: tuple) -> list:
    """One entry per parameter: a number (uniform) or a float32 per-element array."""
    n = int(np.prod(leading, dtype=np.int64))
    entries = []
    for name, info in PARAMETERS.items():
        value = getattr(material, name)
        _require_float32_range(name, value)
        uniform = value.shape == (() if info.slots == 1 else (3,))
        if uniform:
            entries.append(tuple(float(v) for v in value) if info.slots == 3 else float(value))
        else:
            per_element = material._float32(name, leading)
            entries.append(per_element.reshape((n, 3) if info.slots == 3 else (n,)))
    return entries


def _output(out, shape: tuple, name: str = "out") -> np.ndarray:
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
    return out


def _require_material(material) -> None:
    if not isinstance(material, Material):
        raise TypeError(f"material: expected a principled_brdf.Material, got {type(material).__name__}")


def _size(leading: tuple) -> int:
    return int(np.prod(leading, dtype=np.int64))


def _vec3_shape(leading: tuple, layout: str) -> tuple:
    return leading + (3,) if layout == "aos" else (3,) + leading


def _flat_vec3(array: np.ndarray, layout: str) -> tuple:
    n = _size(array.shape[:-1] if layout == "aos" else array.shape[1:])
    return (array.reshape(n, 3), _INTERLEAVED) if layout == "aos" else (array.reshape(3, n), _ROWS)


def _evaluate(material, wi, wo, model_id, cosine, layout, threads, check, isa, outputs_for_shape, pdf_sampler=None):
    """eval / eval_lobes / pdf: validated arguments in, outputs written."""
    _require_material(material)
    layout = _layout(layout)
    thread_count = _threads(threads)
    isa_name = _isa(isa)
    wi_dirs = _Directions("wi", wi, layout)
    wo_dirs = _Directions("wo", wo, layout)
    leading = broadcast_leading(wi=wi_dirs.leading, wo=wo_dirs.leading, material=material.shape)
    outputs, fresh = outputs_for_shape(leading, layout)
    if check and not fresh:
        # The caller's buffer must stay untouched on bad input: check first.
        wi_dirs.check(thread_count)
        wo_dirs.check(thread_count)
    n = _size(leading)
    wi_flat, wi_code = wi_dirs.flat(leading)
    wo_flat, wo_code = wo_dirs.flat(leading)
    # Into fresh outputs the check rides along with the evaluation (one pass
    # over memory instead of two); on a bad direction the partial result is dropped.
    fused_tolerance = DIRECTION_LENGTH_TOLERANCE if check and fresh else 0.0
    params = _params(material, leading)
    if pdf_sampler is not None:
        bad = _core.batch_pdf(wi_flat, wi_code, wo_flat, wo_code, params, outputs[0].reshape(n), n, pdf_sampler,
                              fused_tolerance, thread_count, isa_name)
    else:
        flat_outputs = [_flat_vec3(o, layout)[0] for o in outputs]
        bad = _core.batch_eval(wi_flat, wi_code, wo_flat, wo_code, params, flat_outputs,
                               _INTERLEAVED if layout == "aos" else _ROWS, n, model_id, len(outputs) == 4,
                               bool(cosine), fused_tolerance, thread_count, isa_name)
    if bad >= 0:
        wi_dirs.check(thread_count)
        wo_dirs.check(thread_count)
        raise RuntimeError("internal error: the kernel rejected a direction the checks accept")
    return outputs


def eval(material: Material, wi, wo, *, model: str = "disney2014", cosine: bool = False, layout: str = "aos",
         threads=None, out=None, check: bool = True, isa=None) -> np.ndarray:
    """f(wi, wo) in 1/sr as float32, by the SIMD kernel (SPEC §3).

    ``wi``, ``wo``: unit directions, ``(..., 3)`` or with ``layout="soa"``
    ``(3, ...)``; leading shapes broadcast with each other and with the
    material's. Returns ``(..., 3)`` (``(3, ...)`` for ``"soa"``), written into
    ``out`` if given (float32, C-contiguous, exact shape). ``cosine`` multiplies
    by cos θl. ``threads``: default all cores; results are bit-identical for
    every thread count. ``check=False`` skips the direction checks for speed:
    a non-unit direction is then used as given and a non-finite one gives 0. ``isa``
    picks one of ``cpu_info()["available"]`` (for tests and benchmarks).
    """
    (f,) = _evaluate(material, wi, wo, model_index(model), cosine, layout, threads, check, isa,
                     lambda leading, layout: ([_output(out, _vec3_shape(leading, layout))], out is None))
    return f


def eval_lobes(material: Material, wi, wo, *, model: str = "disney2014", cosine: bool = False, layout: str = "aos",
               threads=None, check: bool = True, isa=None) -> Lobes:
    """The four lobes (diffuse, sheen, specular, clearcoat) as a :class:`Lobes`
    of float32 arrays, each shaped like :func:`eval`'s result."""
    outputs = _evaluate(material, wi, wo, model_index(model), cosine, layout, threads, check, isa,
                        lambda leading, layout: ([np.empty(_vec3_shape(leading, layout), np.float32) for _ in range(4)],
                                                 True))
    return Lobes(*outputs)


def pdf(material: Material, wi, wo, *, specular_sampler: str = "visible", layout: str = "aos", threads=None,
        check: bool = True, isa=None) -> np.ndarray:
    """The density (solid angle) with which :func:`sample` draws ``wi`` given ``wo``:
    the lobe mixture of README "Sampling and pdf", float32 ``(...)``; 0 when
    either direction is at or below the horizon. It does not depend on the model."""
    (density,) = _evaluate(material, wi, wo, 0, False, layout, threads, check, isa,
                           lambda leading, layout: ([np.empty(leading, np.float32)], True),
                           pdf_sampler=_specular_sampler(specular_sampler))
    return density


def random_uniforms(seed: int, n: int, first: int = 0) -> np.ndarray:
    """The ``(n, 3)`` uniforms :func:`sample` draws for elements ``first .. first + n - 1``
    when given ``seed`` and no ``u`` (a counter-based generator keyed by seed and index)."""
    count, start = operator.index(n), operator.index(first)
    if count < 0 or start < 0:
        raise ValueError(f"n, first: expected non-negative integers, got {count}, {start}")
    return _core.counter_uniforms(_seed(seed), start, count)


def sample(material: Material, wo, *, u=None, seed: int = 0, model: str = "disney2014",
           specular_sampler: str = "visible", layout: str = "aos", threads=None, check: bool = True,
           isa=None) -> Sample:
    """Importance-sample ``wi`` for each ``wo`` (README "Sampling and pdf").

    ``u``: three uniforms in [0, 1] per element, ``(..., 3)`` (``(3, ...)`` for
    ``layout="soa"``), broadcast with ``wo`` and the material; without it they
    come from a counter-based generator keyed by ``(seed, element index)``
    (C order over the broadcast leading shape), independent of ``threads``.
    Returns a :class:`Sample` of float32 ``wi``, ``pdf``, ``weight`` and int32 ``lobe``.
    """
    _require_material(material)
    model_id = model_index(model)
    sampler = _specular_sampler(specular_sampler)
    layout = _layout(layout)
    thread_count = _threads(threads)
    isa_name = _isa(isa)
    seed_value = _seed(seed)
    wo_dirs = _Directions("wo", wo, layout)
    shapes = dict(wo=wo_dirs.leading, material=material.shape)
    uniforms = None
    if u is not None:
        uniforms = _Directions("u", u, layout)  # shape and dtype handling of a 3-vector argument
        require_in_domain("u", uniforms.array, 0.0, 1.0)
        shapes["u"] = uniforms.leading
    leading = broadcast_leading(**shapes)
    n = _size(leading)
    wi_out = np.empty(_vec3_shape(leading, layout), np.float32)
    weight_out = np.empty_like(wi_out)
    pdf_out = np.empty(leading, np.float32)
    lobe_out = np.empty(leading, np.int32)
    wo_flat, wo_code = wo_dirs.flat(leading)
    u_flat, u_code = uniforms.flat(leading) if uniforms is not None else (None, 0)
    bad = _core.batch_sample(
        wo_flat, wo_code, u_flat, u_code, seed_value, _params(material, leading), _flat_vec3(wi_out, layout)[0],
        _flat_vec3(weight_out, layout)[0], _INTERLEAVED if layout == "aos" else _ROWS, pdf_out.reshape(n),
        lobe_out.reshape(n), n, model_id, sampler, DIRECTION_LENGTH_TOLERANCE if check else 0.0, thread_count,
        isa_name,
    )
    if bad >= 0:
        wo_dirs.check(thread_count)
        raise RuntimeError("internal error: the kernel rejected a direction the checks accept")
    return Sample(wi_out, pdf_out, weight_out, lobe_out)
