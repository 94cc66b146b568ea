"""Matplotlib pictures of the model for notebooks (optional extra ``plot``).

    import principled_brdf as pb
    import principled_brdf.plot as pbplot

    pbplot.brdf_slice(pb.presets.get("car_paint"))          # (θh, θd) image slice, Axes
    pbplot.polar_lobes(pb.Material(roughness=0.3), 45)      # f in the plane of incidence, polar Axes
    pbplot.lit_sphere(pb.presets.get("gold"))                    # under a key light and a sky, Axes
    pbplot.albedo_curves(pb.presets.get("skin"))            # E(θo) per lobe, Axes
    pbplot.parameter_sweep()                                # Burley 2012 figure 16, Figure
    pbplot.blend_demo("gold", "blue_rubber")                # Material.mix with a mask, Axes
    pbplot.microfacet_family(0.3)                           # D(θh) and Λ(θ) of pb.microfacet, Figure

Every function that draws one panel takes ``ax=`` (an existing Axes to draw
into; a new figure is made when it is None) and returns that Axes;
:func:`parameter_sweep` and :func:`microfacet_family` draw several panels and return the Figure. A material
argument is a :class:`~principled_brdf.Material` or the name of a preset
(``pb.presets.names()``). All numbers come from the batched kernel
(``pb.eval``, ``pb.eval_lobes``, ``pb.sample``, ``pb.albedo``,
``pb.render``) in a few vectorised calls.

Scalar pictures show one channel of the RGB result: ``"luminance"`` (Rec. 709
weights of linear RGB, 0.2126 R + 0.7152 G + 0.0722 B), or ``"r"``, ``"g"``,
``"b"``. A ``resolution`` (pixels, or angles for :func:`polar_lobes` and
:func:`microfacet_family`) is an integer from 2 (8 for :func:`microfacet_family`)
to 16384, ``pb.render.MAX_RESOLUTION``, as ``pb.render.render_sphere``'s; the
errors name the argument. matplotlib is imported on the first call, so ``import principled_brdf``
(and ``import principled_brdf.plot``) work without it.
"""

from __future__ import annotations

import typing

import numpy as np

from . import presets as _presets
from ._batch import eval as _eval
from ._batch import eval_lobes as _eval_lobes
from . import _color, _models, _validate
from .directional_albedo import MAX_SAMPLES as _ALBEDO_MAX_SAMPLES
from .directional_albedo import albedo as _albedo
from .material import Material
from ._gradient import DIFFERENTIABLE as _DIFFERENTIABLE
from . import measured as _measured
from ._data_brdf import data_brdf as _data_brdf
from ._data_brdf import is_data as _is_data
from . import render as _render

if typing.TYPE_CHECKING:  # (typing.TYPE_CHECKING: this module shows its public names only)
    from collections.abc import Callable, Iterable, Mapping
    from types import ModuleType
    from typing import Any

    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.projections.polar import PolarAxes
    from numpy.typing import NDArray

    from ._typing import Float64Array, FloatArray, Model, RealArrayLike
    from .render import _EnvironmentArg

__all__ = ["brdf_slice", "polar_lobes", "lit_sphere", "albedo_curves", "parameter_sweep", "blend_demo",
           "microfacet_family", "slice_directions", "SCALAR_PARAMETERS", "CHANNELS", "ALBEDO_QUADRATURE"]

#: The ten scalar parameters of the 2012 and 2014 models, in the library's order.
SCALAR_PARAMETERS = tuple(name for name, info in _DIFFERENTIABLE.items() if info.slots == 1)

#: Channel names accepted by the scalar plots and their weights on linear RGB.
CHANNELS = {
    "luminance": _color.LUMINANCE_WEIGHTS,
    "r": (1.0, 0.0, 0.0),
    "g": (0.0, 1.0, 0.0),
    "b": (0.0, 0.0, 1.0),
}

_LOBE_COLORS = {"diffuse": "tab:orange", "sheen": "tab:purple", "specular": "tab:blue", "clearcoat": "tab:green",
                "multiple_scattering": "tab:cyan", "transmission": "tab:red", "diffuse_transmission": "tab:brown",
                "reflectance": "tab:olive", "transmittance": "tab:pink", "total": "black"}

# Shading of pb.render.render_sphere, used where many spheres are shaded in one kernel call.
_LIGHT_INTENSITY = 3.0
_BACKGROUND = "0.75"  # masked (undefined) pixels


# --------------------------------------------------------------------------
# argument checks


def _pyplot() -> ModuleType:
    try:
        import matplotlib.pyplot as plt
    except ImportError as error:  # pragma: no cover - depends on the environment
        raise ImportError("principled_brdf.plot needs matplotlib: pip install 'principled-brdf[plot]'") from error
    return plt


def _material(name: str, value: object) -> Material:
    """A Material from a Material or a preset name; TypeError naming ``name`` otherwise."""
    if isinstance(value, Material):
        return value
    if isinstance(value, str):
        try:
            return _presets.get(value)
        except ValueError as error:
            raise ValueError(f"{name}: {error}") from None
    raise TypeError(f"{name}: expected a principled_brdf.Material or a preset name, got {type(value).__name__}")


def _uniform_material(name: str, value: object) -> Material:
    material = _material(name, value)
    if not material.is_uniform:
        raise ValueError(f"{name}: expected a uniform material (one value per parameter), "
                         f"got per-element parameters of shape {material.shape}")
    return material


class _Brdf(typing.NamedTuple):
    """What a plot draws: a uniform material (its lobes too), measured data or any f(wi, wo)."""

    f: Callable[[Float64Array, Float64Array], Float64Array]  # (..., 3) float64 in 1/sr, NaN where no data
    material: Material | None  # set for a Material or a preset: the library's lobes and albedo


def _brdf(name: str, value: object, model: Model, cosine: bool = False) -> _Brdf:
    """A Material, a preset name, a :class:`~principled_brdf.measured.MerlBRDF` or a callable
    ``f(wi, wo) -> (..., 3)`` in 1/sr; errors name ``name``."""
    if isinstance(value, (Material, str)):
        material = _uniform_material(name, value)
        return _Brdf(lambda wi, wo: _eval(material, wi.astype(np.float32), wo.astype(np.float32), model=model,
                                          cosine=cosine).astype(np.float64), material)
    data = _data_brdf(name, value)  # (anything else: a TypeError naming what a plot takes)

    def measured(wi: Float64Array, wo: Float64Array) -> Float64Array:
        f = data(wi, wo)
        return f * np.abs(wi[..., 2:3]) if cosine else f
    return _Brdf(measured, None)


def _channel(value: object) -> Float64Array:
    if not isinstance(value, str) or value not in CHANNELS:
        raise ValueError(f"channel: expected one of {', '.join(repr(c) for c in CHANNELS)}, got {value!r}")
    return np.asarray(CHANNELS[value], dtype=np.float64)


def _axes(ax: Axes | None, polar: bool = False) -> Axes:
    """``ax`` checked, or a new Axes (polar if asked) on a new figure."""
    plt = _pyplot()
    if ax is None:
        fig = plt.figure()
        return fig.add_subplot(projection="polar" if polar else None)
    from matplotlib.axes import Axes

    if not isinstance(ax, Axes):
        raise TypeError(f"ax: expected a matplotlib Axes, got {type(ax).__name__}")
    if polar and ax.name != "polar":
        raise ValueError("ax: expected a polar Axes (e.g. plt.subplot(projection='polar'))")
    return ax


def _project(rgb: RealArrayLike, weights: Float64Array) -> Float64Array:
    return np.asarray(rgb, dtype=np.float64) @ weights


def _rgba(linear: RealArrayLike, inside: NDArray[np.bool_], exposure: float) -> NDArray[np.uint8]:
    """8-bit sRGB with alpha 0 off the sphere, ``(..., R, R, 4)``."""
    rgb = _render.to_srgb8(linear, exposure)
    alpha = np.broadcast_to(np.where(inside, 255, 0).astype(np.uint8), rgb.shape[:-1])
    return np.concatenate([rgb, alpha[..., None]], axis=-1)


def _upper_half_disc(ax: PolarAxes) -> None:
    """The plane of incidence above the surface: the normal at the top, angles positive to the right."""
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_thetamin(-90)
    ax.set_thetamax(90)


def _sphere_axes(ax: Axes, title: str) -> None:
    ax.set_xticks([])
    ax.set_yticks([])
    for spine in ax.spines.values():
        spine.set_visible(False)
    ax.set_title(title)


# --------------------------------------------------------------------------
# 1. BRDF image slice


def slice_directions(resolution: int, phi_d: float = 90.0) -> tuple[FloatArray, FloatArray, Float64Array,
                                                                    Float64Array]:
    """``(theta_h, theta_d, wi, wo)`` of the (θh, θd) slice at ``phi_d`` (degrees).

    ``theta_h``, ``theta_d``: pixel-centre angles in degrees, ``(resolution,)``
    each, from 0 to 90; ``wi``, ``wo``: float64 ``(resolution, resolution, 3)``
    indexed ``[θd, θh]``. Rusinkiewicz's half/difference parametrisation with
    φh = 0: ``h = (sin θh, 0, cos θh)``, ``wi = Ry(θh) d`` and ``wo = Ry(θh) d'``
    with ``d = (sin θd cos φd, sin θd sin φd, cos θd)`` and ``d'`` its
    reflection about z (so ``h`` is their half vector and ``cos θd = wi·h``).
    """
    n = _validate.resolution("resolution", resolution)
    phi = np.radians(_validate.real_number("phi_d", phi_d))
    theta = (np.arange(n) + 0.5) * (90.0 / n)
    th, td = np.meshgrid(np.radians(theta), np.radians(theta))  # [θd, θh]
    sd, cd = np.sin(td), np.cos(td)
    dx, dy = sd * np.cos(phi), sd * np.sin(phi)
    sh, ch = np.sin(th), np.cos(th)

    def rotate(x: Float64Array, y: Float64Array, z: Float64Array) -> Float64Array:  # rotation by θh about y: z -> h
        return np.stack([x * ch + z * sh, y, z * ch - x * sh], axis=-1)

    return theta, theta.copy(), rotate(dx, dy, cd), rotate(-dx, -dy, cd)


def brdf_slice(material: Material | str | _measured.MerlBRDF | Callable[..., Any], *, resolution: int = 256, phi_d: float = 90.0, channel: str = "luminance",
               log: bool = True, model: Model = "disney2014", vmin: float | None = None, vmax: float | None = None,
               percentile: float | None = None, exposure: float = 1.0, cmap: str = "inferno", colorbar: bool = True,
               transmission: bool = False, ax: Axes | None = None) -> Axes:
    """The BRDF image slice f(θh, θd) at azimuth ``phi_d`` (Burley 2012, figures 3, 4 and 17).

    θh (half-vector angle from the normal, degrees) runs left to right from 0
    to 90, θd (difference angle, between the light and the half vector) bottom
    to top from 0 to 90, φh = 0 (see :func:`slice_directions`); the specular
    peak is the left edge, grazing (Fresnel, sheen) the top, retro-reflection
    the bottom right. Pixels where the light or the view is at or below the
    horizon are masked (drawn in grey; NaN-free data underneath).

    ``channel``: one of :data:`CHANNELS`, or ``"rgb"``: the color of f, each
    pixel's brightness set by its luminance on the color scale and its
    chromaticity kept (a grey color bar gives the scale). The color scale
    runs over ``[vmin, vmax]`` in 1/sr; by default up to the ``percentile``-th
    percentile of the slice (default 99 with ``log``, 90 without: a sharp
    specular peak saturates instead of leaving the rest black) and, with
    ``log``, down to 6 decades below that or the smallest positive value
    (linear: from 0). ``exposure`` multiplies
    f before it is mapped (above 1 brightens, the color bar relabelled to
    match). Returns the Axes; the image is ``ax.images[-1]`` (``get_array()``
    gives the plotted values, indexed ``[θd, θh]`` with row 0 at θd ≈ 0).

    ``material``: a uniform Material or a preset name (evaluated by the kernels
    with ``model``), measured data (a :class:`~principled_brdf.measured.MerlBRDF`;
    cells without data are masked like the horizon) or any callable ``f(wi, wo)``
    returning ``(..., 3)`` in 1/sr for float64 ``(..., 3)`` directions, e.g. a
    fitted material beside its measurements.

    ``transmission=True`` (the 2015 models): the slice of the light that passes
    through, ``f(mirror(wi), wo)`` with the light's direction mirrored below the
    surface, at the (θh, θd) of the pair before the mirror; for the thin sheet
    that is its transmitted lobe's own (θh, θd), for the solid a view of the
    refraction's lobe in the same coordinates.
    """
    _validate.model_index(model)
    if _validate.flag("transmission", transmission) and not _models.is_whole_sphere(model):
        raise ValueError(f"transmission: model {model!r} transmits nothing; use a 2015 model")
    brdf = _brdf("material", material, model)
    n = _validate.resolution("resolution", resolution)
    rgb_mode = channel == "rgb"
    weights = np.asarray(CHANNELS["luminance"]) if rgb_mode else _channel(channel)
    _validate.model_index(model)
    value: float | Float64Array | None  # vmin or vmax in the loop, then the projected slice
    for name, value in (("vmin", vmin), ("vmax", vmax)):
        if value is not None and _validate.real_number(name, value, 0.0) <= 0.0 and log:
            raise ValueError(f"{name}: a logarithmic scale needs a positive value, got {value!r}")
    percentile = ((99.0 if log else 90.0) if percentile is None
                  else _validate.real_number("percentile", percentile, 0.0, 100.0, open_lower=True))
    exposure = _validate.real_number("exposure", exposure, 0.0, open_lower=True)
    ax = _axes(ax)
    from matplotlib import colors, cm

    theta_h, theta_d, wi, wo = slice_directions(n, phi_d)
    light = np.asarray(wi, np.float64) * ([1.0, 1.0, -1.0] if transmission else 1.0)
    f = brdf.f(light, np.asarray(wo, np.float64))
    valid = (wi[..., 2] > 0.0) & (wo[..., 2] > 0.0) & ~np.isnan(f).any(axis=-1)
    f = np.where(valid[..., None], f, 0.0)
    value = _project(f, weights)
    shown = value[valid]
    top = float(vmax) if vmax is not None else (float(np.percentile(shown, percentile)) if shown.size else 0.0)
    if not top > 0.0:
        top = float(shown.max()) if shown.size and shown.max() > 0.0 else 1.0
    if vmin is not None:
        bottom = float(vmin)
    elif log:
        positive = shown[shown > 0.0]
        bottom = max(float(positive.min()) if positive.size else top * 1e-6, top * 1e-6)
    else:
        bottom = 0.0
    bottom = min(bottom, top * 0.5)
    # exposure x f is mapped onto [bottom, top]: the scale of f itself is that divided by exposure
    norm = (colors.LogNorm if log else colors.Normalize)(vmin=bottom / exposure, vmax=top / exposure)
    extent = (0.0, 90.0, 0.0, 90.0)
    title = (("BSDF slice, transmission (light mirrored below)" if transmission else "BRDF slice")
             + f", φd = {float(phi_d):g}°" + (f", exposure {exposure:g}" if exposure != 1.0 else ""))

    assert norm.vmin is not None  # set above (for type checkers: Normalize.vmin is float | None)
    if rgb_mode:
        # display brightness (sRGB-encoded) = the luminance's place on the scale, as on the grey color bar
        level = np.clip(np.ma.filled(norm(np.maximum(value, norm.vmin)), 0.0), 0.0, 1.0)
        scale = np.divide(_color.srgb_decode(level), value, out=np.zeros_like(value), where=value > 0.0)
        color = f * scale[..., None]
        color = color / np.maximum(1.0, color.max(axis=-1, keepdims=True))  # keep the hue where it clips
        image = np.empty(color.shape[:-1] + (4,))
        image[..., :3] = np.where(valid[..., None], _color.srgb_encode(color), colors.to_rgb(_BACKGROUND))
        image[..., 3] = 1.0
        ax.imshow(image, origin="lower", extent=extent, interpolation="nearest")
        if colorbar:
            ax.figure.colorbar(cm.ScalarMappable(norm=norm, cmap="gray"), ax=ax,
                               label="f, luminance (1/sr): brightness")
        ax.set_title(title + (" (log scale)" if log else ""))
    else:
        floor = norm.vmin if log else 0.0
        data = np.ma.masked_array(np.where(valid, np.maximum(value, floor), floor), mask=~valid)
        colormap = _pyplot().get_cmap(cmap).with_extremes(bad=_BACKGROUND)
        ax.imshow(data, origin="lower", extent=extent, interpolation="nearest", norm=norm, cmap=colormap)
        if colorbar:
            ax.figure.colorbar(ax.images[-1], ax=ax, label=f"f, {channel} (1/sr)", extend="max")
        ax.set_title(title)
    ax.set_xlabel("θh (degrees)")
    ax.set_ylabel("θd (degrees)")
    ax.set_xticks([0, 30, 60, 90])
    ax.set_yticks([0, 30, 60, 90])
    return ax


# --------------------------------------------------------------------------
# 2. polar plot in the plane of incidence


def polar_lobes(material: Material | str | _measured.MerlBRDF | Callable[..., Any], theta_o: float, *, lobes: bool = True, cosine: bool = False,
                model: Model = "disney2014", resolution: int = 721, channel: str = "luminance", log: bool = False,
                decades: float = 4.0, legend: bool = True, ax: Axes | None = None,
                label: str = "total") -> PolarAxes:
    """f(wi, wo) in the plane of incidence, per lobe and in total, on a polar Axes.

    ``wo = (sin θo, 0, cos θo)`` (``theta_o`` in degrees, in (-90, 90)), ``wi =
    (sin t, 0, cos t)`` for t from -90 to 90 degrees in ``resolution`` steps
    (the 2015 models, BSDFs: ``theta_o`` in (-180, 180), a view from inside or
    below past ±90, and t around the whole circle, so that the transmitted
    lobe shows below the surface's line);
    the angle of the plot is t (0 at the top = the normal, positive to the
    right, the side of wo), the radius is f in 1/sr (``cosine``: f cos θl).
    ``log``: the radius is log10 f over the ``decades`` below the largest
    value (ticks labelled in 1/sr), so a diffuse lobe shows beside a sharp
    specular peak. ``lobes``: also draw the four lobes (lobes that are zero
    everywhere are left out) over a wide grey band of their sum, the
    ``"total"`` line, which stays visible where one lobe is all of it. The
    view direction is drawn as a grey dashed line labelled ``"wo"``. ``ax``
    must be a polar Axes. Returns the polar Axes; lines carry labels
    ``"total"``, ``"diffuse"``, ... (their data: f, or log10 f with ``log``).
    ``material`` may also be measured data or a callable ``f(wi, wo)`` (as for
    :func:`brdf_slice`): then the total alone is drawn, with gaps where there is
    no data, dashed. ``label`` names the total's line (e.g. ``"measured"`` and
    ``"fitted"`` on one Axes).
    """
    _validate.model_index(model)
    brdf = _brdf("material", material, model, cosine=_validate.flag("cosine", cosine))
    span = 180.0 if _models.is_whole_sphere(model) else 90.0  # the circle, or the upper half of it
    theta = _validate.real_number("theta_o", theta_o, -span, span, open_upper=True, open_lower=True)
    n = _validate.resolution("resolution", resolution, unit=" angles")
    weights = _channel(channel)
    decades = _validate.real_number("decades", decades, 0.0, open_lower=True)
    _validate.model_index(model)
    ax = typing.cast("PolarAxes", _axes(ax, polar=True))  # checked: its name is "polar"
    from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator

    t = np.radians(np.linspace(-span, span, n))
    wi = np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=-1)
    wi[np.isclose(np.abs(t), np.pi / 2, rtol=0.0, atol=1e-12), 2] = 0.0  # exactly on the horizon (cos(±π/2) is 6e-17)
    wo = np.array([np.sin(np.radians(theta)), 0.0, np.cos(np.radians(theta))])
    if brdf.material is not None:
        values = _eval_lobes(brdf.material, wi, wo, cosine=cosine, model=model)
        curves = {name: _project(v, weights) for name, v in zip(_models.LOBE_NAMES, values)}
        total = typing.cast("Float64Array", sum(curves.values()))  # (not 0: there are four lobes)
    else:
        curves = {}
        total = _project(brdf.f(wi, np.broadcast_to(wo, wi.shape)), weights)  # NaN (no data): gaps in the line
    peak = float(np.nanmax(total)) if np.nanmax(total, initial=0.0) > 0 else 1.0
    if log:
        floor = np.log10(peak) - decades

        def radius(f: Float64Array) -> Float64Array:  # log10 f above the floor; nothing below it
            return np.maximum(np.log10(np.maximum(f, 1e-300)) - floor, 0.0)
    else:
        def radius(f: Float64Array) -> Float64Array:
            return f

    drawn = [(name, curve) for name, curve in curves.items() if lobes and np.any(curve > 0.0)]
    ax.plot(t, radius(total), color=_LOBE_COLORS["total"], lw=4.0 if drawn else 1.8, alpha=0.3 if drawn else 1.0,
            label=label, zorder=2, ls="-" if brdf.material is not None else "--")
    for name, curve in drawn:
        ax.plot(t, radius(curve), color=_LOBE_COLORS[name], lw=1.3, label=name, zorder=3)
    top = float(radius(np.array(peak)))
    ax.plot([np.radians(theta)] * 2, [0.0, top], color="0.5", ls="--", lw=1.0, label="wo", zorder=1)
    if span == 90.0:
        _upper_half_disc(ax)
    else:  # the whole circle, the normal at the top and the surface as a line through the centre
        ax.set_theta_zero_location("N")
        ax.set_theta_direction(-1)
        for side in (-np.pi / 2, np.pi / 2):
            ax.plot([side, side], [0.0, top * 1.05], color="0.3", lw=0.8, zorder=1)
    ax.set_ylim(0.0, top * 1.05)
    if log:  # a tick per decade (or per few), labelled with f itself
        step = max(1, int(np.ceil(decades / 4)))
        exponents = np.arange(np.ceil(floor), np.floor(np.log10(peak)) + 1, step)
        ax.yaxis.set_major_locator(FixedLocator(exponents - floor))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda r, _: f"{10 ** (r + floor):.3g}"))
    else:
        ax.yaxis.set_major_locator(MaxNLocator(4))
    ax.set_rlabel_position(-22.5)  # along a ray inside the upper-left quarter, clear of the curves' usual peaks
    ax.tick_params(axis="y", labelsize="small")
    quantity = "f cos θl" if cosine else "f"
    ax.set_title(f"{quantity} (1/sr, {channel}{', log radius' if log else ''}), θo = {theta:g}°\n"
                 "plane of incidence; angle θl from the normal", fontsize="medium")
    if legend and span == 90.0:  # below the half disc (its baseline is at axes y = 0.25)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, 0.17), ncol=3, fontsize="small", frameon=False)
    elif legend:
        ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize="small", frameon=False)
    return ax


# --------------------------------------------------------------------------
# 3. lit sphere, optionally with an environment


def lit_sphere(material: Material | str | _measured.MerlBRDF | Callable[..., Any], *, resolution: int = 256, light: RealArrayLike = _render.DEFAULT_LIGHT,
               light_intensity: float | None = None, environment: _EnvironmentArg = "sky",
               environment_samples: int | None = None, seed: int = 0, exposure: float = 1.0,
               model: Model = "disney2014", ax: Axes | None = None, energy_compensation: bool = False) -> Axes:
    """The material on a sphere (``pb.render.render_sphere``), tone mapped to sRGB; returns the Axes.

    ``material`` is uniform or per pixel (leading shape ``(resolution,
    resolution)``). ``light``: direction towards the light in camera space
    (x right, y up, z to the viewer), ``light_intensity`` its irradiance
    scale (0 turns it off; by default 3 with the sky or no environment, 0 with
    a map or a callable). ``environment``: ``"sky"`` (default,
    :func:`pb.render.sky_environment`), ``"studio"``, ``"outdoor"``, a
    ``.exr``/``.hdr`` map or an array, a callable ``L(w)`` (camera-space
    directions ``(..., 3)`` to RGB radiance), or None / False for the light
    alone (``pb.render.environment_of``); its integral ``∫ f L cos θl dωi`` is
    estimated per pixel from ``environment_samples`` lattice points (by default
    64 for the sky or a callable, 256 for a map; deterministic for a ``seed``;
    :func:`pb.render.render_environment`). ``exposure`` scales the linear image
    before the tone curve (``pb.render.tone_map``). Off the sphere is transparent.
    ``energy_compensation`` as in ``pb.eval``. ``material`` may also be data, measured (a
    :class:`~principled_brdf.measured.MerlBRDF`) or any callable ``f(wi, wo)``, as
    ``render_sphere`` takes it (docs/rendering-and-plots.md, "Pictures of data").
    """
    n = _validate.resolution("resolution", resolution)
    exposure = _validate.real_number("exposure", exposure, 0.0)
    intensity = None if light_intensity is None else _validate.real_number("light_intensity", light_intensity, 0.0)
    shown: Material | _measured.MerlBRDF | Callable[..., Any]
    if isinstance(material, (Material, str)) or not _is_data(material):
        shown = _material("material", material)
        if shown.shape not in ((), (n, n)):
            raise ValueError(f"material: expected a uniform material or one of leading shape {(n, n)}, "
                             f"got {shown.shape}")
    else:
        shown = material
    count = None if environment_samples is None else _validate.integer_in(
        "environment_samples", environment_samples, 1, _render.MAX_SAMPLES, " per pixel")
    _validate.model_index(model)
    environment = _render.environment_of(environment)
    ax = _axes(ax)

    image = _render.render_sphere(shown, n, light=light, light_intensity=intensity, model=model,
                                  environment=environment, samples=count, seed=seed,
                                  energy_compensation=energy_compensation)
    inside, _ = _render.sphere_frames(n)
    ax.imshow(_rgba(image, inside, exposure), interpolation="nearest")
    _sphere_axes(ax, "lit sphere" + (" + environment" if environment is not None else ""))
    return ax


# --------------------------------------------------------------------------
# 4. directional albedo


def albedo_curves(material: Material | str | _measured.MerlBRDF | Callable[..., Any], *, angles: RealArrayLike = np.linspace(0, 89, 46), samples: int = 1 << 14,
                  seed: int = 0, model: Model = "disney2014", channel: str = "luminance", lobes: bool = True,
                  ax: Axes | None = None, energy_compensation: bool = False, label: str = "total") -> Axes:
    """Directional albedo ``E(θo) = ∫ f cos θl dωi`` against θo (``pb.albedo``), per lobe and in total.

    ``angles``: view angles in degrees, in [0, 90); for the 2015 models (BSDFs)
    in [0, 180) without 90, a view from inside or below past 90, and the
    total is split into ``"reflectance"`` (wi on the view's side) and
    ``"transmittance"`` (wi on the other), drawn as well. Each point is the mean of
    ``samples`` importance-sampled weights; the bands are ±2 standard errors
    (for ``"luminance"`` the luminance-weighted sum of the per-channel errors,
    an upper bound). Lobes whose albedo is zero at every angle are left out.
    Returns the Axes; lines carry labels ``"total"``, ``"diffuse"``, ...
    (``"multiple_scattering"`` with ``energy_compensation``, as in ``pb.albedo``).

    ``material`` may also be measured data or a callable ``f(wi, wo)`` (as for
    :func:`brdf_slice`): then the total alone is drawn, integrated by the
    midpoint rule on a grid of ``ALBEDO_QUADRATURE`` (cos² θl, φl) cells over
    the upper hemisphere (cells without data count as 0), dashed, without a
    band. ``label`` names the total's line.
    """
    _validate.model_index(model)
    brdf = _brdf("material", material, model)
    weights = _channel(channel)
    theta = np.asarray(angles, dtype=np.float64) if not isinstance(angles, str) else None
    if theta is None or theta.ndim != 1 or theta.size < 1 or not np.all(np.isfinite(theta)):
        raise ValueError("angles: expected a 1-d array of finite angles in degrees")
    sphere = _models.is_whole_sphere(model)
    last = 180.0 if sphere else 90.0
    if np.any(theta < 0.0) or np.any(theta >= last) or np.any(theta == 90.0):
        raise ValueError(f"angles: expected degrees in [0, {last:g}){' without 90' if sphere else ''}, got values "
                         f"from {theta.min():g} to {theta.max():g}")
    _validate.integer_in("samples", samples, 2, _ALBEDO_MAX_SAMPLES)
    _validate.model_index(model)
    ax = _axes(ax)

    if brdf.material is None:
        total = _albedo_by_quadrature(brdf.f, np.radians(theta))
        curves: list[tuple[str, FloatArray, FloatArray]] = [("total", total, np.zeros_like(total))]
    else:
        result = _albedo(brdf.material, np.cos(np.radians(theta)), samples=samples, seed=seed, model=model,
                         energy_compensation=energy_compensation)
        curves = [("total", result.total, result.total_error)]
        if sphere:  # (their standard errors are at most the total's)
            curves += [("reflectance", result.reflectance, result.total_error),
                       ("transmittance", result.transmittance, result.total_error)]
        if lobes:
            curves += [(name, value, error)
                       for name, value, error in zip(_models.LOBE_NAMES, result.lobes, result.lobe_errors)]
    for name, value, error in curves:
        mean, band = _project(value, weights), _project(error, weights) * 2.0
        if name != "total" and not np.any(mean > 0.0):
            continue
        color = _LOBE_COLORS[name]
        ax.plot(theta, mean, color=color, lw=1.8 if name == "total" else 1.2, label=label if name == "total" else name,
                ls="-" if brdf.material is not None else "--")
        ax.fill_between(theta, mean - band, mean + band, color=color, alpha=0.25, lw=0)
    from_below = bool(np.any(theta > 90.0))  # (the whole range only where some view is from inside or below)
    ax.set_xlim(0.0, 180.0 if from_below else 90.0)
    if from_below:
        ax.axvline(90.0, color="0.3", lw=0.8)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("θo (degrees)")
    ax.set_ylabel(f"directional albedo ({channel}, unitless)")
    ax.set_title(f"directional albedo, ±2 s.e. ({samples} samples)" if brdf.material is not None
                 else "directional albedo (quadrature)")
    ax.legend(loc="best", fontsize="small", frameon=False)  # where it covers the fewest points
    return ax


#: (cos² θl cells, φl cells) of the quadrature that :func:`albedo_curves` applies to measured data and callables
ALBEDO_QUADRATURE = (256, 256)


def _albedo_by_quadrature(f: Callable[[Float64Array, Float64Array], Float64Array],
                          theta_o: Float64Array) -> Float64Array:
    """∫ f cos θl dωi over the upper hemisphere, (len(theta_o), 3): with x = cos² θl,
    cos θl dωi = dx dφ / 2, so the midpoint rule in (x, φ) weighs every cell alike."""
    n_x, n_phi = ALBEDO_QUADRATURE
    x = (np.arange(n_x) + 0.5) / n_x
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2.0 * np.pi
    x_, phi_ = np.meshgrid(x, phi, indexing="ij")
    sin = np.sqrt(1.0 - x_)
    wi = np.stack([sin * np.cos(phi_), sin * np.sin(phi_), np.sqrt(x_)], axis=-1).reshape(-1, 3)
    cell = 0.5 * (1.0 / n_x) * (2.0 * np.pi / n_phi)
    totals = []
    for t in theta_o:
        wo = np.broadcast_to([np.sin(t), 0.0, np.cos(t)], wi.shape)
        totals.append(np.nansum(f(wi, wo), axis=0) * cell)
    return np.array(totals)


# --------------------------------------------------------------------------
# 5. parameter sweep (Burley 2012, figure 16)


def _default_sweep_base() -> Material:
    return Material(base_color=(0.5, 0.03, 0.02), roughness=0.5)  # a saturated red: the lobes show against it


def parameter_sweep(base: Material | str | None = None, *, parameters: str | Iterable[str] = SCALAR_PARAMETERS,
                    steps: int = 11, resolution: int = 64, ranges: Mapping[str, tuple[float, float]] | None = None,
                    light: RealArrayLike = _render.DEFAULT_LIGHT, environment: _EnvironmentArg = "sky",
                    exposure: float = 1.0, model: Model = "disney2014",
                    figsize: tuple[float, float] | None = None) -> Figure:
    """The grid of Burley 2012 figure 16: one row per parameter, that parameter
    going from 0 to 1 (or ``ranges[name] = (lo, hi)``) in ``steps`` spheres
    along the row, every other parameter as in ``base``; returns the Figure.

    ``base``: a uniform Material or preset name (default: a red dielectric,
    roughness 0.5). Rows of ``sheen_tint`` and ``clearcoat_gloss`` use
    ``sheen = 1`` / ``clearcoat = 1`` when the base has none, so the tint and
    gloss are visible. All spheres are shaded as ``pb.render.render_sphere``
    does (``environment`` as there), materials batched per pixel, in one
    kernel call per pass. The Figure
    has one Axes per row (in ``fig.axes`` order), each showing its row image.
    """
    base = _default_sweep_base() if base is None else _uniform_material("base", base)
    if isinstance(parameters, str):
        parameters = (parameters,)
    names = tuple(parameters)
    if not names:
        raise ValueError("parameters: expected at least one parameter name")
    for name in names:
        if name not in SCALAR_PARAMETERS:
            raise ValueError(f"parameters: unknown scalar parameter {name!r}; "
                             f"choose from {', '.join(SCALAR_PARAMETERS)}")
    count = _validate.integer_in("steps", steps, 2, _validate.MAX_RESOLUTION)
    n = _validate.resolution("resolution", resolution)
    exposure = _validate.real_number("exposure", exposure, 0.0)
    ranges = {} if ranges is None else dict(ranges)
    for name in ranges:
        if name not in names:
            raise ValueError(f"ranges: {name!r} is not one of the swept parameters")
    spans = []
    for name in names:
        lo, hi = ranges.get(name, (0.0, 1.0))
        spans.append((_validate.real_number(f"ranges[{name!r}]", lo), _validate.real_number(f"ranges[{name!r}]", hi)))

    rows = len(names)
    params: dict[str, Any] = {"base_color": base.base_color}  # (Any: Material(**) also takes a bool keyword)
    for name in SCALAR_PARAMETERS:
        grid = np.full((rows, count), float(getattr(base, name)))
        if name in names:
            lo, hi = spans[names.index(name)]
            grid[names.index(name)] = np.linspace(lo, hi, count)
        params[name] = grid
    for tint, parent in (("sheen_tint", "sheen"), ("clearcoat_gloss", "clearcoat")):
        if tint in names and float(getattr(base, parent)) == 0.0:
            params[parent][names.index(tint)] = 1.0
    try:
        material = Material(**{k: (v[:, :, None, None] if k != "base_color" else v) for k, v in params.items()})
    except ValueError as error:
        raise ValueError(f"ranges: {error}") from None

    linear = _render.render_sphere(material, n, light=light, light_intensity=_LIGHT_INTENSITY, model=model,
                                   environment=environment)
    inside = _render.sphere_frames(n)[0]
    spheres = _rgba(linear, inside, exposure)  # (rows, steps, R, R, 4)
    pad = max(1, n // 16)
    spheres = np.pad(spheres, ((0, 0), (0, 0), (pad, pad), (pad, pad), (0, 0)))
    cell = n + 2 * pad
    strips = spheres.transpose(0, 2, 1, 3, 4).reshape(rows, cell, count * cell, 4)

    plt = _pyplot()
    if figsize is None:
        figsize = (0.75 * count + 2.4, 0.75 * rows + 0.9)
    fig, axes = plt.subplots(rows, 1, figsize=figsize, squeeze=False, layout="constrained")
    for row, (name, (lo, hi)) in enumerate(zip(names, spans)):
        ax = axes[row, 0]
        ax.imshow(strips[row], interpolation="nearest")
        _sphere_axes(ax, "")
        ax.set_ylabel(name, rotation=0, ha="right", va="center")
        ax.text(1.01, 0.5, f"{lo:g} → {hi:g}", transform=ax.transAxes, ha="left", va="center", fontsize="small")
    bottom = axes[-1, 0]
    fractions = np.linspace(0.0, 1.0, count)
    bottom.set_xticks((np.arange(count) + 0.5) * cell)
    bottom.set_xticklabels([f"{x:.2g}" for x in fractions], fontsize="small")
    bottom.set_xlabel("t: each row's parameter = lo + t (hi − lo)")
    fig.suptitle("parameter sweep (Burley 2012, figure 16)")
    return fig


# --------------------------------------------------------------------------
# 6. blending by masks


def _checker(resolution: int, cells: int = 8) -> np.ndarray:
    index = (np.arange(resolution) * cells) // resolution
    return ((index[:, None] + index[None, :]) % 2).astype(np.float64)


def blend_demo(a: Material | str, b: Material | str, *, mask: RealArrayLike | None = None, resolution: int = 256,
               light: RealArrayLike = _render.DEFAULT_LIGHT, environment: _EnvironmentArg = "sky",
               exposure: float = 1.0, model: Model = "disney2014", ax: Axes | None = None) -> Axes:
    """A sphere of ``Material.mix(a, b, mask)`` with a per-pixel mask; returns the Axes.

    ``a``, ``b``: Materials or preset names. ``mask``: weights of ``b`` in
    [0, 1], a number or an array of shape ``(resolution, resolution)`` (row 0
    at the top, like the image); default an 8 x 8 checker. Rendered with
    ``pb.render.render_sphere`` (``environment`` as there).
    """
    a = _material("a", a)
    b = _material("b", b)
    n = _validate.resolution("resolution", resolution)
    exposure = _validate.real_number("exposure", exposure, 0.0)
    if mask is None:
        mask = _checker(n)
    else:
        if isinstance(mask, (str, bytes)):
            raise TypeError(f"mask: expected a number or an array, got {type(mask).__name__}")
        mask = np.asarray(mask, dtype=np.float64)
        if mask.shape not in ((), (n, n)):
            raise ValueError(f"mask: expected a number or shape {(n, n)}, got shape {mask.shape}")
        bad = ~np.isfinite(mask) | (mask < 0.0) | (mask > 1.0)
        if bad.any():
            index = np.unravel_index(int(np.flatnonzero(bad)[0]), mask.shape)
            raise ValueError(f"mask{list(index) if index else ''}: {float(mask[index])!r} is outside [0, 1]")
    material = Material.mix(a, b, np.broadcast_to(mask, (n, n)))
    _validate.model_index(model)
    ax = _axes(ax)
    image = _render.render_sphere(material, n, light=light, model=model, environment=environment)
    inside, _ = _render.sphere_frames(n)
    ax.imshow(_rgba(image, inside, exposure), interpolation="nearest")
    _sphere_axes(ax, "Material.mix(a, b, mask)")
    return ax


# --------------------------------------------------------------------------
# 7. the microfacet family (pb.microfacet)


def _shapes(name: str, values: Iterable[float], lower: float, upper: float, open_lower: bool = False) -> list[float]:
    if isinstance(values, (str, bytes)) or not isinstance(values, typing.Iterable):
        raise TypeError(f"{name}: expected a sequence of numbers, got {type(values).__name__}")
    return [_validate.real_number(f"{name}[{k}]", value, lower, upper, open_lower=open_lower)
            for k, value in enumerate(values)]


def _family_axes(axes: object) -> tuple[Axes, Axes] | None:
    if axes is None:
        return None
    from matplotlib.axes import Axes

    if isinstance(axes, (str, bytes)) or not isinstance(axes, typing.Sequence) or len(axes) != 2:
        raise TypeError(f"axes: expected two matplotlib Axes (D and Λ), got {type(axes).__name__}")
    for k, ax in enumerate(axes):
        if not isinstance(ax, Axes):
            raise TypeError(f"axes[{k}]: expected a matplotlib Axes, got {type(ax).__name__}")
        if ax.name == "polar":
            raise ValueError(f"axes[{k}]: expected a rectilinear Axes, got a polar one")
    return axes[0], axes[1]


def microfacet_family(alpha: float = 0.3, *, student_t_gammas: Iterable[float] = (1.6, 4.0),
                      exponential_power_ps: Iterable[float] = (0.5, 2.0), gtr_gammas: Iterable[float] = (1.0, 1.5),
                      resolution: int = 361, decades: float = 10.0, legend: bool = True,
                      axes: tuple[Axes, Axes] | None = None, figsize: tuple[float, float] = (11.0, 4.4)) -> Figure:
    """The distributions of ``pb.microfacet`` at one roughness ``alpha`` (isotropic, in (0, 1]):
    ``D(θh)`` against θh (left) and Smith's ``Λ(θ)`` against the angle of the direction (right),
    both on a logarithmic scale so that the tails show; returns the Figure.

    Drawn: GGX, Beckmann, Blinn-Phong at the exponent that matches ``alpha`` (``n = 2/α² - 2``,
    Walter et al. 2007), Student-t at each of ``student_t_gammas`` (γ > 3/2; Ribardière et al.
    2017: γ = 2 is GGX, γ -> ∞ Beckmann), exponential power at each of ``exponential_power_ps``
    (p in [0.1, 10]; Holzschuch & Pacanowski 2017: p = 1 is Beckmann) and, in the D panel only,
    GTR at each of ``gtr_gammas`` (γ in (0, 1e6]; Burley 2012 appendix B: γ = 1 is the clear
    coat's GTR1, γ = 2 GGX), which is not shape-invariant and has no closed-form Λ (README
    "The microfacet family"). ``Λ`` is at ``w = (sin θ, 0, cos θ)``; ``G1 = 1 / (1 + Λ)``
    (Smith masking, Heitz 2014). Each panel shows the ``decades`` below its largest value; a line stops
    where it falls below that floor, so every plotted value is finite and positive.
    ``resolution`` angles from 0 to 90 degrees (90 itself left out: ``Λ`` is infinite there).

    ``axes``: two existing Axes to draw into (D, then Λ); by default a new Figure with two.
    Both panels carry the same line labels (``"GGX"``, ``"Beckmann"``, ``"Student-t γ = 1.6"``,
    ...); the legend (``legend``) is on the D panel.
    """
    a = _validate.real_number("alpha", alpha, 0.0, 1.0, open_lower=True)
    gammas = _shapes("student_t_gammas", student_t_gammas, 1.5, 1e12, open_lower=True)
    ps = _shapes("exponential_power_ps", exponential_power_ps, 0.1, 10.0)
    gtrs = _shapes("gtr_gammas", gtr_gammas, 0.0, 1e6, open_lower=True)
    n = _validate.resolution("resolution", resolution, minimum=8, unit=" angles")
    decades = _validate.real_number("decades", decades, 0.0, open_lower=True)
    drawn = _family_axes(axes)
    from . import microfacet as mf

    theta = np.linspace(0.0, 90.0, n, endpoint=False)
    radians = np.radians(theta)
    w = np.stack([np.sin(radians), np.zeros_like(radians), np.cos(radians)], axis=-1)
    exponent = 2.0 / a**2 - 2.0
    # (label, color, line style, D(h), Λ(w) or None)
    curves: list[tuple[str, str, str | tuple[int, tuple[int, ...]], Float64Array, Float64Array | None]] = [
        ("GGX", "tab:blue", "-", mf.GGX(a).d(w), mf.GGX(a).lambda_(w)),
        ("Beckmann", "tab:orange", "-", mf.Beckmann(a).d(w), mf.Beckmann(a).lambda_(w)),
        (f"Blinn-Phong (n = {exponent:.3g})", "tab:green", "--", mf.BlinnPhong(a).d(w), mf.BlinnPhong(a).lambda_(w)),
    ]
    shades = ("tab:purple", "tab:pink", "tab:olive", "tab:cyan")
    curves += [(f"Student-t γ = {g:g}", shades[k % len(shades)], "-.", mf.StudentT(a, gamma=g).d(w),
                mf.StudentT(a, gamma=g).lambda_(w)) for k, g in enumerate(gammas)]
    shades = ("tab:red", "tab:brown", "darkgoldenrod", "maroon")
    curves += [(f"exponential power p = {p:g}", shades[k % len(shades)], ":", mf.ExponentialPower(a, p=p).d(w),
                mf.ExponentialPower(a, p=p).lambda_(w)) for k, p in enumerate(ps)]
    shades = ("0.35", "0.6", "0.15", "0.75")
    curves += [(f"GTR γ = {g:g}" + (" (GTR1)" if g == 1.0 else ""), shades[k % len(shades)], (0, (5, 1, 1, 1)),
                mf.GTR(a, g).d(w), None) for k, g in enumerate(gtrs)]

    if drawn is None:
        fig, (d_ax, lambda_ax) = _pyplot().subplots(1, 2, figsize=figsize, layout="constrained")
    else:
        d_ax, lambda_ax = drawn
        fig = typing.cast("Figure", d_ax.figure)
    panels = ((d_ax, [(label, color, style, d) for label, color, style, d, _ in curves]),
              (lambda_ax, [(label, color, style, lam) for label, color, style, _, lam in curves if lam is not None]))
    for ax, lines in panels:
        top = max(float(np.max(value[np.isfinite(value)])) for *_, value in lines)
        floor = top * 10.0 ** -decades
        for label, color, style, value in lines:
            keep = np.isfinite(value) & (value >= floor) & (value > 0.0)
            ax.plot(theta[keep], value[keep], color=color, ls=style, lw=1.4, label=label)
        ax.set_yscale("log")
        ax.set_ylim(floor, top * 3.0)
        ax.set_xlim(0.0, 90.0)
        ax.set_xticks([0, 15, 30, 45, 60, 75, 90])
        ax.grid(True, which="major", color="0.9", lw=0.6)
    d_ax.set_xlabel("θh (degrees)")
    d_ax.set_ylabel("D(θh) (1/sr)")
    d_ax.set_title(f"normal distributions D, α = {a:g}")
    lambda_ax.set_xlabel("θ of the direction (degrees)")
    lambda_ax.set_ylabel("Λ(θ) (Smith; G1 = 1 / (1 + Λ))")
    lambda_ax.set_title(f"Smith Λ, α = {a:g} (GTR: no closed form)")
    if legend:
        d_ax.legend(loc="lower left", fontsize="small", frameon=False)
    return fig
