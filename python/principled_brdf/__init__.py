"""Disney principled BRDF: evaluation and sampling over numpy arrays of directions.

See the README for the model and the API tour.
"""

from . import (environment, frames, measured, microfacet, piecewise, plot, presets, procedural_environments, reference,
               render, synthetic)
from .fitting import FitResult, fit
from ._batch import cpu_info, eval, eval_lobes, eval_pdf, pdf, random_uniforms, sample
from ._derivatives import DIRECTION_NAMES, eval_grad, eval_vjp
from ._gradient import GRADIENT_NAMES
from ._results import Gradient, Lobes, Sample, ValuePdf
from ._results import Albedo
from .directional_albedo import albedo
from .material import PARAMETERS, BrightColorWarning, Material, gamma22_to_linear, linear_to_srgb, srgb_to_linear

__all__ = [
    "Material", "PARAMETERS", "BrightColorWarning", "srgb_to_linear", "linear_to_srgb", "gamma22_to_linear",
    "eval", "eval_lobes", "eval_pdf", "pdf", "sample", "random_uniforms", "cpu_info",
    "Lobes", "Sample", "ValuePdf", "Albedo", "albedo",
    "eval_grad", "eval_vjp", "Gradient", "GRADIENT_NAMES", "DIRECTION_NAMES", "fit", "FitResult",
    "reference", "microfacet", "measured", "synthetic", "frames", "presets", "render", "plot",
    "environment", "procedural_environments", "piecewise",
]
from .explorer_app import explorer  # noqa: E402 - ipywidgets and matplotlib are imported by the call
__all__.append("explorer")
__version__ = "0.2.0"
