"""The float64 reference's calls (docs/model.md, "The model"): the arguments checked
and laid out as rows for the C++ reference, its results shaped back. ``reference``
shows them; the derivatives in the directions join them in ``_derivatives``."""

from __future__ import annotations

import typing

import numpy as np

from . import _core, _gradient, _models, _validate
from ._model_checks import model_and_mode
from ._results import Gradient, Lobes, Sample
from .material import Material, require_material

if typing.TYPE_CHECKING:
    from collections.abc import Callable

    from numpy.typing import NDArray

    from ._typing import Float64Array, Layout, Mode, Model, RealArrayLike, SpecularSampler

    _Scalar = typing.TypeVar("_Scalar", bound=np.generic)

__all__ = ["eval", "eval_lobes", "sample", "pdf", "lobe_probabilities", "parameter_grad", "direction_grad"]


def _is_soa(layout: object) -> bool:
    """True for "soa" ((3, ...) arrays, as the SIMD calls take them), False for "aos"."""
    return _validate.layout(layout) == "soa"


def _as_aos(name: str, value: RealArrayLike, soa: bool) -> RealArrayLike:
    """A 3-vector argument with its components last: ``(3, ...)`` moved for layout="soa"."""
    if not soa:
        return value
    array = _validate.as_real_array(name, value)
    if array.ndim == 0 or array.shape[0] != 3:
        raise ValueError(f"{name}: expected shape (3, ...) with layout='soa', got {array.shape}")
    return np.moveaxis(array, 0, -1)


def _as_layout(array: NDArray[_Scalar], soa: bool, trailing: int = 1) -> NDArray[_Scalar]:
    """A result with its ``trailing`` last axes moved to the front for layout="soa"."""
    if not soa:
        return array
    return np.ascontiguousarray(np.moveaxis(array, tuple(range(-trailing, 0)), tuple(range(trailing))))


def _prepare(material: Material, wi: RealArrayLike, wo: RealArrayLike,
             model: Model) -> tuple[tuple[int, ...], Float64Array, Float64Array, Float64Array, int]:
    require_material("material", material)
    model_id = _validate.model_index(model)
    material.require_read_by(model)
    wi = _validate.directions("wi", wi)
    wo = _validate.directions("wo", wo)
    shape = _validate.broadcast_leading(wi=wi.shape[:-1], wo=wo.shape[:-1], material=material.shape)
    rows: Callable[[Float64Array], Float64Array] = (  # noqa: E731
        lambda w: np.ascontiguousarray(np.broadcast_to(w, shape + (3,)).reshape(-1, 3)))
    return shape, rows(wi), rows(wo), _material_rows(material, shape), model_id


def eval(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model = "disney2014",
         cosine: bool = False, layout: Layout = "aos", energy_compensation: bool = False,
         mode: Mode = "radiance") -> Float64Array:
    """f(wi, wo) in 1/sr as float64 ``(..., 3)`` (``(3, ...)`` for ``layout="soa"``); times ``|cos θl|`` if ``cosine``."""
    soa = _is_soa(layout)
    shape, wi_rows, wo_rows, params, model_id = _prepare(material, _as_aos("wi", wi, soa), _as_aos("wo", wo, soa), model)
    mode_id = model_and_mode(material, model, mode, energy_compensation)[1]
    cosine = _validate.flag("cosine", cosine)
    f = _core.reference_eval(wi_rows, wo_rows, params, model_id, False,
                             _validate.flag("energy_compensation", energy_compensation), mode_id)
    if cosine:
        f *= _cosine_factor(wi_rows[:, 2:3], model)
    return _as_layout(f.reshape(shape + (3,)), soa)


def parameter_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *,
                   wrt: str | list[str] | tuple[str, ...] | None = None, model: Model = "disney2014",
                   cosine: bool = False, layout: Layout = "aos", energy_compensation: bool = False,
                   mode: Mode = "radiance") -> Gradient:
    """pb.reference.eval_grad in the parameters only (its arguments, checked as it checks them)."""
    _validate.refuse_energy_compensation_derivative(energy_compensation, model)
    mode_id = model_and_mode(material, model, mode, energy_compensation)[1]
    compensated = _validate.flag("energy_compensation", energy_compensation)
    soa = _is_soa(layout)
    shape, wi_rows, wo_rows, params, model_id = _prepare(material, _as_aos("wi", wi, soa), _as_aos("wo", wo, soa), model)
    cosine = _validate.flag("cosine", cosine)
    names = _gradient.gradient_names(model)
    wanted = _gradient.columns(wrt, names=names)
    value, jacobian = _core.reference_eval_grad(wi_rows, wo_rows, params, model_id, mode_id, compensated)
    if cosine:
        cos_theta_l = _cosine_factor(wi_rows[:, 2], model)
        value *= cos_theta_l[:, None]
        jacobian *= cos_theta_l[:, None, None]
    result = _gradient.result(value.reshape(shape + (3,)), jacobian.reshape(shape + jacobian.shape[1:]), wanted, names)
    return Gradient(_as_layout(result.value, soa), _as_layout(result.jacobian, soa, trailing=2), result.names)


def direction_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model, cosine: bool,
                   layout: Layout, mode_id: int, energy_compensation: bool = False) -> Float64Array:
    """f's derivatives in the six direction components, ``(..., 3, 6)`` (``(3, 6, ...)``
    for ``layout="soa"``), by the model's forward mode in float64."""
    soa = _is_soa(layout)
    shape, wi_rows, wo_rows, params, model_id = _prepare(material, _as_aos("wi", wi, soa), _as_aos("wo", wo, soa), model)
    jacobian = _core.reference_eval_direction_grad(wi_rows, wo_rows, params, model_id, _validate.flag("cosine", cosine),
                                                   mode_id, _validate.flag("energy_compensation", energy_compensation))
    return _as_layout(jacobian.reshape(shape + jacobian.shape[1:]), soa, trailing=2)


def eval_lobes(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model = "disney2014",
               cosine: bool = False, layout: Layout = "aos", energy_compensation: bool = False,
               mode: Mode = "radiance") -> Lobes:
    """The lobes as a :class:`Lobes` of float64 ``(..., 3)`` (``(3, ...)``) arrays
    (multiple_scattering 0 unless ``energy_compensation``, transmission 0 but for the 2015 models, diffuse_transmission but for the thin sheet)."""
    soa = _is_soa(layout)
    shape, wi_rows, wo_rows, params, model_id = _prepare(material, _as_aos("wi", wi, soa), _as_aos("wo", wo, soa), model)
    mode_id = model_and_mode(material, model, mode, energy_compensation)[1]
    cosine = _validate.flag("cosine", cosine)
    lobes = _core.reference_eval(wi_rows, wo_rows, params, model_id, True,
                                 _validate.flag("energy_compensation", energy_compensation), mode_id)
    if cosine:
        lobes *= _cosine_factor(wi_rows[:, None, 2:3], model)
    return Lobes(*(_as_layout(lobes[:, k, :].reshape(shape + (3,)), soa) for k in range(len(Lobes._fields))))


def _cosine_factor(cos_theta_l: Float64Array, model: str) -> Float64Array:
    """``|cos θl|`` for the 2015 models (directions on the whole sphere), cos θl clamped at 0 for the BRDFs."""
    return np.abs(cos_theta_l) if _models.is_whole_sphere(model) else np.maximum(cos_theta_l, 0.0)


# --------------------------------------------------------------------------
# sampling (docs/sampling.md)


def _uniforms(name: str, value: RealArrayLike) -> Float64Array:
    """A float64 ``(..., 3)`` array of numbers in [0, 1], checked (docs/bad-input.md)."""
    array = _validate.as_real_array(name, value)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"{name}: expected shape (..., 3) with (u0, u1, u2) on the last axis, got {array.shape}")
    _validate.require_in_domain(name, array, 0.0, 1.0)
    return array


def _shared_or_rows(array: Float64Array, shape: tuple[int, ...], columns: int) -> Float64Array:
    """``(1, columns)`` when the argument is one row for every element, else ``(N, columns)`` rows."""
    if array.size == columns:
        return np.ascontiguousarray(array.reshape(1, columns))
    return np.ascontiguousarray(np.broadcast_to(array, shape + (columns,)).reshape(-1, columns))


def _material_rows(material: Material, shape: tuple[int, ...]) -> Float64Array:
    return material.packed(()) if material.is_uniform else material.packed(shape)


def _to_shape(rows: NDArray[_Scalar], shape: tuple[int, ...], trailing: tuple[int, ...] = ()) -> NDArray[_Scalar]:
    """The binding's output rows as ``shape + trailing``; a single row (every input was
    one shared row) is repeated."""
    n = int(np.prod(shape, dtype=np.int64))
    if rows.shape[0] != n:
        rows = np.repeat(rows, n, axis=0)
    return rows.reshape(shape + trailing)


def sample(material: Material, wo: RealArrayLike, u: RealArrayLike, *, model: Model = "disney2014",
           specular_sampler: SpecularSampler = "visible", layout: Layout = "aos",
           energy_compensation: bool = False, mode: Mode = "radiance") -> Sample:
    """Draws ``wi`` for each ``wo`` from the three-lobe mixture of docs/sampling.md.

    ``u`` holds three uniforms in [0, 1] per element, ``(u0, u1, u2)`` on the last
    axis: ``u0`` chooses the lobe, ``u1, u2`` the direction. ``material``, ``wo``
    and ``u`` broadcast over their leading shapes. Returns a :class:`Sample` of
    float64 arrays (``lobe`` int32); ``pdf`` is the mixture density, the number
    :func:`pdf` gives for the returned pair, and ``weight = f cos θl / pdf``;
    both are 0 when ``wi`` or ``wo`` is at or below the horizon. ``layout="soa"``:
    ``wo``, ``u``, ``wi`` and ``weight`` as ``(3, ...)``. ``model="disney2015"``:
    the mixture over the whole sphere (lobe 3 the transmission, 4 the thin sheet's
    diffuse transmission) and
    ``weight = f |cos θl| / pdf`` in ``mode``.
    """
    require_material("material", material)
    model_id, mode_id = model_and_mode(material, model, mode, energy_compensation)
    sampler_id = _validate.sampler_index(specular_sampler)
    soa = _is_soa(layout)
    wo = _validate.directions("wo", _as_aos("wo", wo, soa))
    u = _uniforms("u", _as_aos("u", u, soa))
    shape = _validate.broadcast_leading(wo=wo.shape[:-1], u=u.shape[:-1], material=material.shape)
    if int(np.prod(shape, dtype=np.int64)) == 0:
        empty = _as_layout(np.zeros(shape + (3,)), soa)
        return Sample(empty, np.zeros(shape), empty.copy(), np.zeros(shape, np.int32))
    wi, density, weight, lobe = _core.reference_sample(
        _shared_or_rows(wo, shape, 3), _shared_or_rows(u, shape, 3), _material_rows(material, shape),
        model_id, sampler_id, _validate.flag("energy_compensation", energy_compensation), mode_id)
    return Sample(_as_layout(_to_shape(wi, shape, (3,)), soa), _to_shape(density, shape),
                  _as_layout(_to_shape(weight, shape, (3,)), soa), _to_shape(lobe, shape))


def pdf(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, model: Model = "disney2014",
        specular_sampler: SpecularSampler = "visible", layout: Layout = "aos",
        energy_compensation: bool = False) -> Float64Array:
    """The mixture density ``P0 pdf0 + P1 pdf1 + P2 pdf2`` of ``wi`` given ``wo``, float64 ``(...)``.

    For the 2012 and 2014 models: 0 unless both directions lie strictly above the
    horizon, and the same for both models unless ``energy_compensation``, whose
    lobe's weight reads the model's tables. The 2015 models each have their own
    mixture over the whole sphere, with the transmission's terms (docs/sampling.md).
    """
    require_material("material", material)
    model_id = model_and_mode(material, model, energy_compensation=energy_compensation)[0]
    sampler_id = _validate.sampler_index(specular_sampler)
    soa = _is_soa(layout)
    wi = _validate.directions("wi", _as_aos("wi", wi, soa))
    wo = _validate.directions("wo", _as_aos("wo", wo, soa))
    shape = _validate.broadcast_leading(wi=wi.shape[:-1], wo=wo.shape[:-1], material=material.shape)
    if int(np.prod(shape, dtype=np.int64)) == 0:
        return np.zeros(shape)
    density = _core.reference_pdf(_shared_or_rows(wi, shape, 3), _shared_or_rows(wo, shape, 3),
                                  _material_rows(material, shape), model_id, sampler_id,
                                  _validate.flag("energy_compensation", energy_compensation))
    return _to_shape(density, shape)


def lobe_probabilities(material: Material, wo: RealArrayLike, *, model: Model = "disney2014",
                       energy_compensation: bool = False) -> Float64Array:
    """``(P0, P1, P2)`` on the last axis, ``(..., 3)``: the chances of the cosine, primary
    specular and clearcoat lobes at ``wo`` (docs/sampling.md); with
    ``energy_compensation`` the cosine lobe's includes the multiple-scattering lobe's.
    The 2015 models: ``(..., 5)``, then the transmission's and the diffuse transmission's
    (``SAMPLED_LOBE_NAMES``; 0 but for ``disney2015_thin``)."""
    require_material("material", material)
    model_id = model_and_mode(material, model, energy_compensation=energy_compensation)[0]
    compensated = _validate.flag("energy_compensation", energy_compensation)
    wo = _validate.directions("wo", wo)
    shape = _validate.broadcast_leading(wo=wo.shape[:-1], material=material.shape)
    rules = _models.RULES[model]  # (the model checked above)
    # the whole-sphere models report every sampled lobe's chance, the BRDFs those they draw
    lobes = len(_models.SAMPLED_LOBE_NAMES) if rules.whole_sphere else len(rules.sampled_lobes)
    if int(np.prod(shape, dtype=np.int64)) == 0:
        return np.zeros(shape + (lobes,))
    p = _core.reference_lobe_probabilities(_shared_or_rows(wo, shape, 3), _material_rows(material, shape), model_id,
                                           compensated)
    return _to_shape(p, shape, (lobes,))
