"""Disney principled BRDF: evaluation and sampling over numpy arrays of directions.

See the README for the model (SPEC §3) and the API tour.
"""

from . import microfacet, reference
from .material import PARAMETERS, Material, gamma22_to_linear

__all__ = ["Material", "PARAMETERS", "gamma22_to_linear", "reference", "microfacet"]
__version__ = "0.1.0"
