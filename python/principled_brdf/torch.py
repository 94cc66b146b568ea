"""The kernels as PyTorch operations on CPU tensors (docs/interop.md).

``eval`` is differentiable in the material's parameters and in ``wi`` and
``wo``: its backward pass is the library's vector-Jacobian product (float32 kernels for float32 inputs, the
float64 reference when any input is float64), once (no double backward). ``pdf`` and ``sample`` take and
return tensors without gradients.

    import torch
    from principled_brdf import torch as pbt
    roughness = torch.full((64, 64), 0.5, requires_grad=True)
    f = pbt.eval({"roughness": roughness, "base_color": (0.9, 0.6, 0.2)}, wi, wo)
    f.sum().backward()
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

try:
    import torch
    from torch.autograd.function import once_differentiable
except ImportError as error:  # pragma: no cover - the test extra installs torch
    raise ImportError("principled_brdf.torch needs PyTorch: pip install 'principled-brdf[torch]'") from error

from . import _batch, _interop, reference
from ._validate import broadcast_leading, directions, integer, seed_value
from .material import Material

if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import SupportsIndex

    from ._typing import Mode, Model, SpecularSampler

__all__ = ["eval", "pdf", "sample", "TensorSample"]


def _numpy(name: str, value: torch.Tensor) -> np.ndarray:
    """A float32 or float64 CPU tensor's data without a copy (any stride numpy can view);
    ValueError or TypeError naming ``name`` for any other tensor."""
    if value.device.type != "cpu":
        raise ValueError(f"{name}: expected a CPU tensor, got one on {value.device}")
    if value.layout != torch.strided:
        raise TypeError(f"{name}: expected a dense tensor, got layout {value.layout}")
    if value.dtype not in (torch.float32, torch.float64):
        raise _interop.dtype_error(name, value.dtype, "tensor", "tensor.float()")
    return value.detach().numpy()


def _host(name: str, value: Any) -> Any:
    """A parameter for pb.Material: a tensor's data (checked), anything else as given."""
    return _numpy(name, value) if isinstance(value, torch.Tensor) else value


def _direction(name: str, value: Any) -> torch.Tensor:
    """A direction as a tensor: one as given (checked), or a number/array read as pb.eval reads it (a constant)."""
    if isinstance(value, torch.Tensor):
        _numpy(name, value)
        return value
    return torch.tensor(_interop.real_array(name, value))


def _is_double(*values: Any) -> bool:
    return any(isinstance(v, torch.Tensor) and v.dtype == torch.float64 for v in values)


class _Eval(torch.autograd.Function):
    """f(wi, wo) with the gradients of the directions and the material's parameters as the backward pass."""

    @staticmethod
    def forward(ctx: Any, material: Material, names: list[str], options: dict[str, Any], double: bool,
                wi: torch.Tensor, wo: torch.Tensor, *values: Any) -> torch.Tensor:
        # ``values``: the parameters as given, for autograd to see; ``material`` holds them checked
        ctx.material, ctx.names, ctx.options, ctx.double = material, names, options, double
        ctx.save_for_backward(wi, wo, *(v if isinstance(v, torch.Tensor) else None for v in values))
        return torch.from_numpy(_interop.evaluate(material, _numpy("wi", wi), _numpy("wo", wo), double, options))

    @staticmethod
    def backward(ctx: Any, grad_output: torch.Tensor) -> tuple[Any, ...]:
        # the inputs as arguments, so that once_differentiable sees those that require grad
        return _backward(ctx, grad_output, *ctx.saved_tensors)


@once_differentiable
def _backward(ctx: Any, grad_output: torch.Tensor, wi: torch.Tensor, wo: torch.Tensor,
              *values: torch.Tensor | None) -> tuple[Any, ...]:
    """The gradients of ``(wi, wo, *values)`` that autograd asks for. Not differentiable itself:
    with create_graph=True they come with a grad_fn that refuses a second backward pass."""
    asked = ctx.needs_input_grad[4:]  # wi, wo, then the parameters
    cotangents = _interop.backward(ctx.material, ctx.names, _numpy("wi", wi), _numpy("wo", wo),
                                   _numpy("cotangent", grad_output), asked, ctx.double, ctx.options)
    return (None, None, None, None, *(None if c is None else torch.from_numpy(c) for c in cotangents))


def _material_items(material: Mapping[str, Any] | Material) -> tuple[list[str], list[Any]]:
    if isinstance(material, Material):
        return list(material.as_dict()), list(material.as_dict().values())
    if not hasattr(material, "items"):
        raise TypeError(f"material: expected a principled_brdf.Material or a mapping of parameter names to tensors, "
                        f"got {type(material).__name__}")
    names = _interop.parameter_names(material)
    return names, [material[name] for name in names]


def _checked_material(material: Mapping[str, Any] | Material, names: list[str], values: list[Any]) -> Material:
    """A pb.Material as given, or one of the named values, checked as pb.Material checks them."""
    if isinstance(material, Material):
        return material
    return _interop.material_of(names, [_host(name, v) for name, v in zip(names, values)])


def eval(material: Mapping[str, Any] | Material, wi: torch.Tensor, wo: torch.Tensor,
         **options: Any) -> torch.Tensor:
    """f(wi, wo) as a tensor ``(..., 3)``, differentiable in the parameters.

    ``material``: a mapping of parameter names to tensors or numbers (the others
    take their defaults), or a :class:`principled_brdf.Material`; every value is
    checked as ``pb.Material`` checks it, tensors are float32 or float64 on the CPU.
    Parameters and directions broadcast as in :func:`principled_brdf.eval`. ``options``:
    ``model``, ``cosine``, ``mode``. Float64 inputs are evaluated by the float64
    reference, float32 ones by the SIMD kernels (the result has that dtype).
    Gradients flow to every parameter tensor and direction that requires them;
    a direction's is the derivative of f in the 3-vector as given (project it
    onto the tangent plane of the unit sphere yourself; docs/gradients.md). The
    backward pass is not differentiable itself (``once_differentiable``).
    """
    names, values = _material_items(material)
    options = _interop.check_options(options)
    double = _is_double(wi, wo, *values)
    pb_material = _checked_material(material, names, values)  # (the model's rules: by eval itself)
    wi, wo = _direction("wi", wi), _direction("wo", wo)
    return _Eval.apply(pb_material, names, options, double, wi, wo, *values)  # type: ignore[no-untyped-call]


def _direction_array(name: str, value: Any) -> np.ndarray:
    return _numpy(name, value) if isinstance(value, torch.Tensor) else _interop.real_array(name, value)


def pdf(material: Mapping[str, Any] | Material, wi: torch.Tensor, wo: torch.Tensor, *, model: Model = "disney2014",
        specular_sampler: SpecularSampler = "visible", energy_compensation: bool = False) -> torch.Tensor:
    """:func:`principled_brdf.pdf` on tensors (no gradient); float64 inputs use the reference."""
    names, values = _material_items(material)
    pb_material = _checked_material(material, names, values)
    options: dict[str, Any] = dict(model=model, specular_sampler=specular_sampler,
                                   energy_compensation=energy_compensation)
    wi_array, wo_array = _direction_array("wi", wi), _direction_array("wo", wo)
    if _is_double(wi, wo, *values):
        return torch.from_numpy(reference.pdf(pb_material, wi_array, wo_array, **options))
    return torch.from_numpy(_batch.pdf(pb_material, wi_array, wo_array, **options))


class TensorSample(NamedTuple):
    """:class:`principled_brdf.Sample` as tensors."""

    wi: torch.Tensor
    pdf: torch.Tensor
    weight: torch.Tensor
    lobe: torch.Tensor


def _drawn_uniforms(material: Material, wo: np.ndarray, seed: SupportsIndex | None,
                    n: SupportsIndex | None) -> np.ndarray:
    """The uniforms pb.sample draws for ``seed`` and ``n`` (its counter-based generator, over
    the leading shape ``(n,) +`` that of ``wo`` and the material), for the float64 reference."""
    leading = broadcast_leading(wo=directions("wo", wo).shape[:-1], material=material.shape)
    if n is not None:
        count = integer("n", n)
        if count < 0:
            raise ValueError(f"n: expected a count >= 0, got {count}")
        leading = (count,) + leading
    drawn = _batch.random_uniforms(_batch._fresh_seed() if seed is None else seed_value(seed), math.prod(leading))
    return drawn.reshape(leading + (3,)).astype(np.float64)


def sample(material: Mapping[str, Any] | Material, wo: torch.Tensor, *, u: torch.Tensor | None = None,
           seed: SupportsIndex | None = None, n: SupportsIndex | None = None, model: Model = "disney2014",
           specular_sampler: SpecularSampler = "visible", energy_compensation: bool = False,
           mode: Mode = "radiance") -> TensorSample:
    """:func:`principled_brdf.sample` on tensors (no gradient): the float32 kernels, or the
    float64 reference when ``wo`` or a parameter is float64. ``u``, ``seed`` and ``n`` as
    ``pb.sample`` takes them on both paths (the reference draws ``pb.sample``'s uniforms
    for ``seed``)."""
    names, values = _material_items(material)
    pb_material = _checked_material(material, names, values)
    options: dict[str, Any] = dict(model=model, specular_sampler=specular_sampler,
                                   energy_compensation=energy_compensation, mode=mode)
    wo_array = _direction_array("wo", wo)
    uniforms = None if u is None else _direction_array("u", u)
    if not _is_double(wo, *values):
        drawn = _batch.sample(pb_material, wo_array, u=uniforms, seed=seed, n=n, **options)
    elif uniforms is not None:
        if n is not None:
            raise ValueError("n: not with u (the uniforms give the number of samples)")
        drawn = reference.sample(pb_material, wo_array, uniforms, **options)
    else:
        drawn = reference.sample(pb_material, wo_array, _drawn_uniforms(pb_material, wo_array, seed, n), **options)
    return TensorSample(*(torch.from_numpy(np.asarray(a)) for a in drawn))
