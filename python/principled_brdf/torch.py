"""The kernels as PyTorch operations on CPU tensors (docs/interop.md).

``eval`` is differentiable in the material's parameters and in ``wi`` and
``wo``: its backward pass is the library's vector-Jacobian product (float32 kernels for float32 inputs, the
float64 reference when any input is float64). ``pdf`` and ``sample`` take and
return tensors without gradients.

    import torch
    from principled_brdf import torch as pbt
    roughness = torch.full((64, 64), 0.5, requires_grad=True)
    f = pbt.eval({"roughness": roughness, "base_color": (0.9, 0.6, 0.2)}, wi, wo)
    f.sum().backward()
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

try:
    import torch
except ImportError as error:  # pragma: no cover - the test extra installs torch
    raise ImportError("principled_brdf.torch needs PyTorch: pip install 'principled-brdf[torch]'") from error

from . import _batch, _interop, reference
from .material import Material

if TYPE_CHECKING:
    from collections.abc import Mapping

__all__ = ["eval", "pdf", "sample", "TensorSample"]


def _numpy(name: str, value: Any) -> np.ndarray:
    """A tensor's data without a copy (CPU, any stride numpy can view), or a plain number/array."""
    if isinstance(value, torch.Tensor):
        if value.device.type != "cpu":
            raise ValueError(f"{name}: expected a CPU tensor, got one on {value.device}")
        if value.is_complex() or not value.is_floating_point():
            raise TypeError(f"{name}: expected a real floating-point tensor, got {value.dtype}")
        return value.detach().resolve_conj().numpy()
    return np.asarray(value, dtype=np.float64)


def _tensor(name: str, value: Any, dtype: torch.dtype) -> torch.Tensor:
    """A tensor as given, or a number/array as a tensor of ``dtype`` (a constant: no gradient)."""
    if isinstance(value, torch.Tensor):
        return value
    return torch.tensor(_numpy(name, value), dtype=dtype)


def _is_double(*values: Any) -> bool:
    return any(isinstance(v, torch.Tensor) and v.dtype == torch.float64 for v in values)


class _Eval(torch.autograd.Function):
    """f(wi, wo) with the gradients of the material's parameters as the backward pass."""

    @staticmethod
    def forward(ctx: Any, names: list[str], options: dict[str, Any], double: bool,
                wi: torch.Tensor, wo: torch.Tensor, *values: torch.Tensor) -> torch.Tensor:
        ctx.names, ctx.options, ctx.double = names, options, double
        ctx.save_for_backward(wi, wo, *values)
        arrays = [_numpy(name, v) for name, v in zip(names, values)]
        return torch.from_numpy(_interop.evaluate(names, arrays, _numpy("wi", wi), _numpy("wo", wo), double, options))

    @staticmethod
    def backward(ctx: Any, grad_output: torch.Tensor) -> tuple[Any, ...]:
        wi, wo, *values = ctx.saved_tensors
        arrays = [_numpy(name, v) for name, v in zip(ctx.names, values)]
        wanted = list(ctx.needs_input_grad[5:])
        wi_array, wo_array, g = _numpy("wi", wi), _numpy("wo", wo), _numpy("grad_output", grad_output)
        gradients = _interop.vjp(ctx.names, arrays, wi_array, wo_array, g, wanted, ctx.double, ctx.options)
        as_tensors = [None if g is None else torch.from_numpy(np.ascontiguousarray(g)) for g in gradients]
        by_wi = by_wo = None
        if ctx.needs_input_grad[3] or ctx.needs_input_grad[4]:
            by_wi, by_wo = (torch.from_numpy(np.ascontiguousarray(d)) for d in
                            _interop.direction_vjp(ctx.names, arrays, wi_array, wo_array, g, ctx.double, ctx.options))
        return (None, None, None, by_wi if ctx.needs_input_grad[3] else None,
                by_wo if ctx.needs_input_grad[4] else None, *as_tensors)


def _material_items(material: Mapping[str, Any] | Material) -> tuple[list[str], list[Any]]:
    if isinstance(material, Material):
        return list(material.as_dict()), list(material.as_dict().values())
    if not hasattr(material, "items"):
        raise TypeError(f"material: expected a principled_brdf.Material or a mapping of parameter names to tensors, "
                        f"got {type(material).__name__}")
    names = _interop.parameter_names(material)
    return names, [material[name] for name in names]


def eval(material: Mapping[str, Any] | Material, wi: torch.Tensor, wo: torch.Tensor,
         **options: Any) -> torch.Tensor:
    """f(wi, wo) as a tensor ``(..., 3)``, differentiable in the parameters.

    ``material``: a mapping of parameter names to tensors or numbers (the others
    take their defaults), or a :class:`principled_brdf.Material`. Parameters and
    directions broadcast as in :func:`principled_brdf.eval`. ``options``:
    ``model``, ``cosine``, ``mode``. Float64 inputs are evaluated by the float64
    reference, float32 ones by the SIMD kernels (the result has that dtype).
    Gradients flow to every parameter tensor and direction that requires them;
    a direction's is the derivative of f in the 3-vector as given (project it
    onto the tangent plane of the unit sphere yourself; docs/gradients.md).
    """
    names, values = _material_items(material)
    options = _interop.check_options(options)
    double = _is_double(wi, wo, *values)
    dtype = torch.float64 if double else torch.float32
    wi, wo, *values = (_tensor(name, v, dtype) for name, v in zip(["wi", "wo", *names], [wi, wo, *values]))
    return _Eval.apply(names, options, double, wi, wo, *values)  # type: ignore[no-untyped-call]


def pdf(material: Mapping[str, Any] | Material, wi: torch.Tensor, wo: torch.Tensor, **options: Any) -> torch.Tensor:
    """:func:`principled_brdf.pdf` on tensors (no gradient); float64 inputs use the reference."""
    names, values = _material_items(material)
    arrays = [_numpy(name, v) for name, v in zip(names, values)]
    pb_material = _interop.material_of(names, arrays)
    if _is_double(wi, wo, *values):
        return torch.from_numpy(reference.pdf(pb_material, _numpy("wi", wi), _numpy("wo", wo), **options))
    return torch.from_numpy(_batch.pdf(pb_material, _numpy("wi", wi).astype(np.float32, copy=False),
                                       _numpy("wo", wo).astype(np.float32, copy=False), **options))


class TensorSample(NamedTuple):
    """:class:`principled_brdf.Sample` as tensors."""

    wi: torch.Tensor
    pdf: torch.Tensor
    weight: torch.Tensor
    lobe: torch.Tensor


def sample(material: Mapping[str, Any] | Material, wo: torch.Tensor, **options: Any) -> TensorSample:
    """:func:`principled_brdf.sample` on tensors (no gradient; float32 kernels, or
    the float64 reference for float64 inputs, which then needs ``u=``)."""
    names, values = _material_items(material)
    arrays = [_numpy(name, v) for name, v in zip(names, values)]
    pb_material = _interop.material_of(names, arrays)
    if "u" in options:
        options["u"] = _numpy("u", options["u"])
    if _is_double(wo, *values):
        drawn = reference.sample(pb_material, _numpy("wo", wo), **options)
    else:
        drawn = _batch.sample(pb_material, _numpy("wo", wo).astype(np.float32, copy=False), **options)
    return TensorSample(*(torch.from_numpy(np.asarray(a)) for a in drawn))
