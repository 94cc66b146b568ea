"""Disney principled BRDF: evaluation and sampling over numpy arrays of directions.

See the README for the model and the API tour.
"""

from . import microfacet, plot, presets, reference, render
from .fit import FitResult, fit
from ._batch import Lobes, Sample, cpu_info, eval, eval_grad, eval_lobes, pdf, random_uniforms, sample
from ._gradient import GRADIENT_NAMES, Gradient
from .albedo import Albedo, albedo
from .material import PARAMETERS, Material, gamma22_to_linear

__all__ = ["Material", "PARAMETERS", "Lobes", "Sample", "Albedo", "albedo", "gamma22_to_linear", "eval", "eval_lobes", "pdf", "sample",
           "eval_grad", "Gradient", "GRADIENT_NAMES", "fit", "FitResult", "random_uniforms", "cpu_info", "reference", "microfacet", "presets", "render", "plot"]
__version__ = "0.1.0"
