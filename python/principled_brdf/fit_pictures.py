"""A fit beside its data: the data (measured or any f(wi, wo)) and the fitted
material rendered on a sphere under the same light, and their difference
(:meth:`principled_brdf.fitting.FitResult.compare`)."""

from __future__ import annotations

import typing

import numpy as np

from . import _validate
from ._batch import eval as _eval
from ._data_brdf import data_brdf
from .render import render_sphere, to_srgb8

if typing.TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

    from matplotlib.figure import Figure

    from ._typing import Float32Array, Float64Array, Model
    from .material import Material
    from .measured import MerlBRDF

__all__ = ["Comparison", "compare"]

DEFAULT_ENVIRONMENTS = ("studio", "outdoor")


class Comparison(typing.NamedTuple):
    """Linear RGB pictures ``(E, resolution, resolution, 3)``, one per environment, and the
    relative L2 error of the fit's picture against the data's, per environment."""

    environments: tuple[str, ...]
    data: Float32Array
    fit: Float32Array
    image_error: tuple[float, ...]

    def figure(self, exposure: float = 1.0) -> Figure:
        """The pictures side by side (a row per environment: data, fit, |data - fit| x 4), tone
        mapped, with the image error in each row's title (matplotlib)."""
        import matplotlib.pyplot as plt

        rows = len(self.environments)
        figure, axes = plt.subplots(rows, 3, figsize=(9.0, 3.1 * rows), squeeze=False)
        for row, name in enumerate(self.environments):
            difference = 4.0 * np.abs(self.data[row] - self.fit[row])
            for column, (title, image) in enumerate((("data", self.data[row]), ("fit", self.fit[row]),
                                                     ("|data - fit| x 4", difference))):
                axis = axes[row, column]
                axis.imshow(to_srgb8(image, exposure=exposure))
                axis.set_axis_off()
                axis.set_title(f"{title}, {name}" if column < 2 else
                               f"{title}\nimage error {self.image_error[row]:.1%}", fontsize=9)
        figure.tight_layout()
        return figure


def compare(material: Material, model: Model, data: MerlBRDF | Callable[..., Any], *,
            environments: Sequence[str] = DEFAULT_ENVIRONMENTS, resolution: int = 128,
            samples: int = 256, seed: int = 0) -> Comparison:
    """The uniform ``material`` (of ``model``) and ``data`` (a MerlBRDF or a callable
    ``f(wi, wo)``, as :func:`~principled_brdf.render.render_sphere` takes them) rendered under
    each of ``environments`` (names or anything ``environment=`` takes, no key light), with
    ``samples`` per pixel. Both go through the data's estimator (a cosine lobe's draws and the
    map's) on the same points, so that their difference is the BRDFs' and not the sampling
    noise's, and where the data has no value (NaN) neither picture takes one. The image
    error is ``‖data - fit‖ / ‖data‖`` over the pixels. Data without a value anywhere is a
    ValueError naming ``data``."""
    if not getattr(material, "is_uniform", False):
        raise ValueError("material: expected one fitted material (for a batch, pick its texel: result.compare(data, "
                         "texel=...))")
    f = data_brdf("data", data)
    values_seen = [0]

    def measured(wi: Float64Array, wo: Float64Array) -> Float64Array:
        values = f(wi, wo)
        values_seen[0] += int(np.count_nonzero(~np.isnan(values)))
        return values

    def fitted(wi: Float64Array, wo: Float64Array) -> Float64Array:
        values = _eval(material, wi.astype(np.float32), wo.astype(np.float32), model=model).astype(np.float64)
        # where the data has no value, neither picture takes one: the difference stays the BRDFs'
        return np.where(np.isnan(f(wi, wo)), np.nan, values)
    if isinstance(environments, str) or len(environments) == 0:
        raise ValueError(f"environments: expected a non-empty sequence of environments, got {environments!r}")
    resolution = _validate.resolution("resolution", resolution)
    data_pictures, fit_pictures, errors = [], [], []
    for environment in environments:
        def picture(brdf: Callable[..., Any]) -> Float32Array:
            return render_sphere(brdf, resolution, environment=environment, samples=samples, seed=seed,
                                 light_intensity=0.0)
        data_pictures.append(picture(measured))
        if values_seen[0] == 0:
            raise ValueError("data: no value at any pair the pictures use (f is NaN, no data, everywhere)")
        # the fit through the data's estimator, on the same points: the difference is the BRDFs', not the noise's
        fit_pictures.append(picture(fitted))
        norm = float(np.linalg.norm(data_pictures[-1]))
        errors.append(float(np.linalg.norm(data_pictures[-1] - fit_pictures[-1])) / norm if norm > 0.0 else np.inf)
    return Comparison(tuple(str(e) for e in environments), np.stack(data_pictures), np.stack(fit_pictures),
                      tuple(errors))
