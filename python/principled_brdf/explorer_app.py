"""An interactive BRDF explorer for Jupyter, after Disney's BRDF Explorer (ipywidgets).

    import principled_brdf as pb
    explorer = pb.explorer()              # the last line of a cell shows it
    explorer = pb.explorer("car_paint", model="disney2012", resolution=256)

A slider per material parameter (``base_color`` as a color picker, sRGB
converted to linear by :func:`principled_brdf.srgb_to_linear`), the model,
a preset menu that sets the sliders, the light and view directions (θ, φ in
degrees, local frame: normal z, tangent x) and four pictures that follow
them, each a PNG in an ``ipywidgets.Image`` (``explorer.images[name]``):

``"sphere"``
    the material on a sphere (``pb.render.render_sphere``, orthographic from
    +z) lit from (θl, φl) in camera space (x right, y up): at the centre of
    the sphere, whose normal faces the viewer, that is the light of the
    sliders in the local frame. ``environment light`` adds the ``environment``
    menu's (``pb.render``'s sky, the studio or the outdoor map) by importance
    sampling; ``exposure`` in stops, then ``pb.render.to_srgb8``. With the 2015
    models light passes through the sphere (``render_sphere``).
``"polar"``
    f (luminance, 1/sr) per lobe and in total in the plane of incidence of
    the view direction (θv, φv): wi sweeps the plane through the normal and
    wo; the light is drawn projected into that plane. ``log radius`` shows
    four decades below the next power of ten above the peak. With the 2015
    models the whole circle (the transmitted lobe below the surface), and
    the view θ goes to 180° (from inside or below).
``"slice"``
    the (θh, θd) image slice at φd = 90° (``pb.plot.slice_directions``), log
    luminance, with the light/view pair's (θh, θd) marked.
``"albedo"``
    the directional albedo E(θo) per lobe and in total (``pb.albedo``, ±2
    standard errors), with θv marked; to 180° with the 2015 models.

Every number comes from the batched kernel. A picture is recomputed only when
something it shows changes (a view angle does not re-render the sphere), and
the figures are made once and their data replaced, which keeps an update
within a few tenths of a second. The explorer works headless (no display,
no kernel): tests set ``explorer.sliders["roughness"].value`` and read
``explorer.images["sphere"].value``.
"""

from __future__ import annotations

import asyncio
import base64
import contextlib
import functools
import math
import time
from typing import TYPE_CHECKING, cast

import numpy as np

from . import _color, _models, _validate
from . import presets as _presets
from . import render as _render
from ._batch import FLOAT32_LIMITS as _KERNEL_LIMITS
from ._batch import eval_lobes as _eval_lobes
from .directional_albedo import albedo as _albedo
from ._models import unread_parameters
from .material import PARAMETERS, Material, srgb_to_linear
from .plot import _LOBE_COLORS as _PLOT_LOBE_COLORS
from .plot import CHANNELS, _rgba, _uniform_material, _upper_half_disc, slice_directions

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator, Mapping
    from types import ModuleType
    from typing import Any, Protocol

    from matplotlib.figure import Figure
    from matplotlib.image import FigureImage
    from matplotlib.projections.polar import PolarAxes
    from numpy.typing import NDArray

    from ._typing import Float32Array, Float64Array, FloatArray, Model, RealArrayLike

    class _AggCanvas(Protocol):  # what is used of FigureCanvasAgg (its methods are not annotated)
        def draw(self) -> None: ...
        def buffer_rgba(self) -> memoryview: ...

__all__ = ["explorer", "Explorer", "OUTPUTS", "CUSTOM"]

#: The pictures, in display order (keys of :attr:`Explorer.images`).
OUTPUTS = ("sphere", "polar", "slice", "albedo")
#: The preset menu's entry for a material that is not (or no longer) a preset.
CUSTOM = "(custom)"

_LUMINANCE = np.asarray(CHANNELS["luminance"], dtype=np.float64)
# plot's colors; the multiple-scattering lobe counts in the totals without a line of its own
_LOBE_COLORS = {name: color for name, color in _PLOT_LOBE_COLORS.items()
                if name in _models.LOBE_NAMES + ("total",) and name != "multiple_scattering"}
# What each picture shows (keys of Explorer._state): it is redrawn only when one of these changes.
_DEPENDS = {
    "sphere": ("material", "model", "energy_compensation", "light", "exposure", "sky", "environment"),
    "polar": ("material", "model", "energy_compensation", "light", "view", "log"),
    "slice": ("material", "model", "energy_compensation", "light", "view"),
    "albedo": ("material", "model", "energy_compensation", "view"),
}


def _inputs(name: str, state: Mapping[str, Any]) -> tuple[Any, ...]:
    """What picture ``name`` shows of ``state``: under a map the sphere has no key light (the map
    brings its lights), so the light's direction does not change it (None in its place)."""
    lit_by_map = state["sky"] and state["environment"] != "sky"
    return tuple(None if (name == "sphere" and k == "light" and lit_by_map) else state[k] for k in _DEPENDS[name])



def _pass_samples(state: Mapping[str, Any], first: bool = True) -> int:
    """Samples per pixel of a pass of the sphere: the first keeps its picture near 0.2 s, the
    others take twice as many."""
    lit_by_map = state["sky"] and state["environment"] != "sky"
    if _models.is_whole_sphere(state["model"]):
        samples = _THROUGH_SAMPLES // 2 if lit_by_map else _THROUGH_SAMPLES
    else:
        samples = _MAP_SAMPLES if lit_by_map else _SKY_SAMPLES
    return samples if first else 2 * samples


_KEY_STYLES: dict[str, dict[str, Any]] = {  # the legend entries of the plots, beyond the lobes
    "wo": dict(color="0.45", ls="--", lw=1.0, label="view"),
    "wi": dict(color="tab:red", ls=":", lw=1.4, label="light (projected)"),
    "θv": dict(color="0.45", ls="--", lw=1.0, label="θv"),
}
# a slider's value within this many steps of its grid is on it: the front end sends 130 back as
# 130.00000000000003, which would otherwise redraw the pictures and stay in the value
_ECHO = 1e-9
# the controls: labels wide enough for the longest ("exposure (stops)") at the notebook's font
_LABEL_WIDTH = "118px"
_CONTROL_WIDTH = "340px"
_PANEL_WIDTH = "350px"
_UI_MAX = 1.0  # the BRDF Explorer's slider range for the unbounded parameters (their domains go on)
_MAX_EXPOSURE_STOPS = 64.0  # |exposure| a slider takes (2^64: far beyond any picture, and finite)
_POLAR_STEPS = 360
_POLAR_DECADES = 4
_SLICE_RESOLUTION = 128
_ALBEDO_ANGLES = np.concatenate([np.arange(0.0, 85.0, 5.0), [84.0, 87.0, 89.0]])  # denser where E(θo) turns
# the 2015 models' (BSDFs): views from below too, mirrored about the horizon
_ALBEDO_ANGLES_SPHERE = np.concatenate([_ALBEDO_ANGLES, 180.0 - _ALBEDO_ANGLES[::-1]])
_HALF_DISC_AXES = (0.117, 0.028, 0.767, 1.023)  # the polar plot's Axes: a half disc of radius 135 px over the legend
_DISC_AXES = (0.27, 0.2, 0.46, 0.6)  # the whole circle, radius 79 px, between the legend and the title
_ALBEDO_SAMPLES = 1 << 12
_SKY_SAMPLES = 32  # render_sphere uses 64; 32 shows little grain and keeps an update near 0.2 s
# the first picture's samples per pixel where light must be found in a map's bright spots or through the
# sphere, each first picture near 0.2 s on two cores (the 2015 models under a map: 2); the passes after it
# take twice as many, while the controls rest
_MAP_SAMPLES = 8
_THROUGH_SAMPLES = 4
_REFINED_SAMPLES = 512  # samples per pixel at which the refinement stops
_REFINE_DELAY = 0.05  # seconds between passes, in which the kernel answers the front end
_AMBIENT = 0.03  # times base_color, without the sky: the unlit side is not black
_DPI = 80
_FIGSIZE = (4.4, 3.3)
_FONT = {"font.size": 8.0, "axes.titlesize": 8.5, "legend.fontsize": 7.5}


def _imports() -> tuple[ModuleType, ModuleType, type[Figure]]:
    try:
        import ipywidgets
    except ImportError as error:
        raise ImportError("pb.explorer() needs ipywidgets: pip install ipywidgets "
                          "(or pip install 'principled-brdf[plot]')") from error
    try:
        import matplotlib
        from matplotlib.figure import Figure
    except ImportError as error:
        raise ImportError("pb.explorer() needs matplotlib: pip install matplotlib "
                          "(or pip install 'principled-brdf[plot]')") from error
    return ipywidgets, matplotlib, Figure


@functools.lru_cache(maxsize=None)
def _slider_class(widgets: ModuleType) -> type[Any]:
    """A FloatSlider that refuses NaN, infinities and values beyond ``limit`` in magnitude:
    setting one raises a ``traitlets.TraitError`` that is also a ``ValueError`` naming the
    slider, and the slider keeps its value (finite values outside its range are clamped to
    it, as a FloatSlider does)."""
    import traitlets

    class RefusedValue(traitlets.TraitError, ValueError):
        """A value a slider of the explorer does not take."""

    float_slider: Any = widgets.FloatSlider  # (ipywidgets is untyped)

    class Slider(float_slider):  # type: ignore[misc]  # a subclass of Any
        name = ""  # what errors call it (not a trait)
        limit = math.inf

        @traitlets.validate("value")
        def _validate_value(self, proposal: Mapping[str, Any]) -> float:
            value = float(proposal["value"])
            if not math.isfinite(value):
                raise RefusedValue(f"{self.name}: {value!r} is not a finite number (the slider keeps {self.value!r})")
            if abs(value) > self.limit:
                raise RefusedValue(f"{self.name}: {value!r} is beyond {self.limit:g}, the most it takes "
                                   f"(the slider keeps {self.value!r})")
            steps = value / self.step if self.step else 0.0
            if steps and abs(steps - round(steps)) < _ECHO:  # the front end's rounding of a value on the grid
                value = round(round(steps) * self.step, 12)
            return cast(float, super()._validate_value(dict(proposal, value=value)))

    Slider.__qualname__ = Slider.__name__ = "FiniteFloatSlider"
    RefusedValue.__qualname__ = RefusedValue.__name__ = "RefusedSliderValue"
    RefusedValue.__module__ = Slider.__module__ = __name__
    return Slider


def _hex(linear: RealArrayLike) -> str:
    return "#" + "".join(f"{int(round(v * 255.0)):02x}" for v in _color.srgb_encode(linear))


def _picked(value: str) -> tuple[float, ...]:
    """The ColorPicker's value (``#rrggbb``, ``#rgb`` or a CSS color name, sRGB) as linear RGB."""
    from matplotlib.colors import to_rgb

    srgb = np.round(np.asarray(to_rgb(value.strip())) * 255.0).astype(np.uint8)
    return tuple(float(v) for v in srgb_to_linear(srgb))


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _power_of_ten(value: float, position: int | None = None) -> str:
    """Tick label ``10³`` for a power of ten (plain text: no mathtext to parse), else empty."""
    if not value > 0.0:
        return ""
    exponent = math.log10(value)
    if abs(exponent - round(exponent)) > 1e-6:
        return ""
    return "10" + str(int(round(exponent))).translate(_SUPERSCRIPT)


def _direction(theta_degrees: float, phi_degrees: float) -> Float64Array:
    theta, phi = math.radians(theta_degrees), math.radians(phi_degrees)
    cos_theta = 0.0 if theta_degrees == 90.0 else math.cos(theta)  # on the horizon, not 6e-17 above it
    return np.array([math.sin(theta) * math.cos(phi), math.sin(theta) * math.sin(phi), cos_theta])


def _uniform(material: object) -> tuple[Material, str | None]:
    """(Material, preset name or None) from None, a uniform Material or a preset name."""
    if material is None:
        return Material(), None
    return _uniform_material("material", material), material if isinstance(material, str) else None


class Explorer:
    """The widget of :func:`explorer`: controls, four PNG images and the state behind them.

    Attributes (all ipywidgets): ``sliders`` (``{name: FloatSlider}`` for the
    scalar parameters, ranges from ``pb.PARAMETERS``' domains; those the model
    does not read are disabled and count at their defaults),
    ``base_color`` (ColorPicker, sRGB), ``model``, ``preset``, ``environment``
    (Dropdowns), ``light_theta``, ``light_phi``, ``view_theta``, ``view_phi`` (degrees),
    ``exposure`` (stops), ``sky``, ``log_radius`` (Checkboxes),
    ``energy_compensation`` (a Checkbox: ``energy_compensation=`` of every
    picture's kernel calls), ``images`` (``{name: Image}`` for
    :data:`OUTPUTS`), ``status`` (HTML: the last update's time) and
    ``widget``, the whole layout; the Explorer displays as that widget.
    ``timings``: seconds each picture took when last drawn;
    ``last_update_seconds``: the last update's total. Methods:
    :meth:`set_material`, :meth:`reset`, :meth:`hold` (several changes, one
    update), :meth:`refresh`, :meth:`write_pngs`, :meth:`close`.

    The sliders clamp a finite value to their range (as a FloatSlider does)
    and refuse NaN, infinities, material values beyond what the kernels take
    (``roughness`` 1e4, the others 1e20) and exposures beyond ±64 stops: the
    assignment raises a ``traitlets.TraitError`` that is also a ``ValueError``
    naming the slider, which keeps its last value. After :meth:`close` the
    explorer is inert: changes to its controls are ignored.
    """

    # (the widgets are ipywidgets', untyped: Any)
    sliders: dict[str, Any]
    images: dict[str, Any]
    timings: dict[str, float]
    _rendered: dict[str, tuple[Any, ...]]
    _figures: dict[str, Figure]
    _legend_cache: dict[tuple[tuple[str, ...], int, bool], NDArray[np.float32]]
    _sphere: dict[str, Any]  # what it shows but the exposure: key, material, state, sum of passes, samples
    _initial: tuple[Material, str | None, dict[Any, tuple[Any, float | None]]]
    _polar: dict[str, Any]  # the polar plot's Axes, angles, lines, legend image and title
    _slice: dict[str, Any]
    _albedo: dict[str, Any]

    def __init__(self, material: Material | str | None = None, *, model: Model = "disney2014",
                 resolution: int = 192) -> None:
        widgets, self._matplotlib, Figure = _imports()
        material, preset = _uniform(material)
        _validate.model_index(model)
        resolution = _validate.resolution("resolution", resolution)
        self.resolution = resolution
        self._holding = 0
        self._quiet = False  # while the preset menu sets the sliders
        self._closed = False
        self._rendered = {}
        self.timings = {}
        self.last_update_seconds = 0.0
        self._base_color = tuple(float(c) for c in material.base_color)
        self._inside = _render.sphere_frames(resolution)[0]
        self._sphere = {"key": None, "samples": 0}
        self._refinement: Any = None  # the event loop's handle of the next pass, while one is scheduled
        self._timing_status = self._timing_detail = ""

        style = {"description_width": _LABEL_WIDTH}
        layout = widgets.Layout(width=_CONTROL_WIDTH)

        Slider = _slider_class(widgets)

        def slider(description: str, value: float, lower: float, upper: float, step: float,
                   fmt: str = ".2f", name: str = "", limit: float = math.inf) -> Any:
            control = Slider(value=value, min=lower, max=upper, step=step, description=description,
                             continuous_update=True, readout_format=fmt, style=style, layout=layout)
            control.name, control.limit = name or description, limit
            return control

        self.sliders = {}
        for name, info in PARAMETERS.items():
            if info.slots != 1:
                continue
            value = float(getattr(material, name))
            upper = info.upper if math.isfinite(info.upper) else max(_UI_MAX, math.ceil(value))
            self.sliders[name] = slider(name, value, info.lower, upper, 0.01, limit=_KERNEL_LIMITS.get(name, math.inf))
        self.base_color = widgets.ColorPicker(value=_hex(self._base_color), description="base_color", concise=False,
                                              style=style, layout=layout)
        self.model = widgets.Dropdown(options=list(_models.MODEL_NAMES), value=model, description="model", style=style,
                                      layout=layout)
        self.preset = widgets.Dropdown(options=[CUSTOM] + _presets.names(), value=preset or CUSTOM,
                                       description="preset", style=style, layout=layout)
        theta_l, phi_l = self._default_light()
        self.light_theta = slider("light θ (°)", theta_l, 0.0, 90.0, 0.5, ".1f", "light_theta")
        self.light_phi = slider("light φ (°)", phi_l, 0.0, 360.0, 1.0, ".0f", "light_phi")
        self.view_theta = slider("view θ (°)", 45.0, 0.0, 90.0, 0.5, ".1f", "view_theta")
        self.view_phi = slider("view φ (°)", 0.0, 0.0, 360.0, 1.0, ".0f", "view_phi")
        self.exposure = slider("exposure (stops)", 0.0, -4.0, 4.0, 0.25, "+.2f", "exposure", _MAX_EXPOSURE_STOPS)
        self.sky = widgets.Checkbox(value=True, description="environment light on the sphere", indent=False)
        self.environment = widgets.Dropdown(options=list(_render.ENVIRONMENT_NAMES), value="sky",
                                            description="environment", style=style, layout=layout)
        self.log_radius = widgets.Checkbox(value=False, description="log radius (polar)", indent=False)
        self.energy_compensation = widgets.Checkbox(value=False, description="energy compensation", indent=False)

        self.images = {name: widgets.Image(format="png") for name in OUTPUTS}
        self.status = widgets.HTML()
        self._figures = {}
        self._Figure, self._legend_cache = Figure, {}
        self._figures_size = (round(_FIGSIZE[0] * _DPI), round(_FIGSIZE[1] * _DPI))
        with self._matplotlib.rc_context(_FONT):
            self._build_polar(Figure)
            self._build_slice(Figure)
            self._build_albedo(Figure)

        for control in self._controls():
            if control is self.preset:
                control.observe(self._preset_chosen, names="value")
            elif control is self.base_color:
                control.observe(self._color_picked, names="value")
            else:
                control.observe(self._changed, names="value")

        def header(text: str) -> Any:
            return widgets.HTML(f"<b>{text}</b>")

        def cell(image: Any) -> Any:
            return widgets.Box([image], layout=widgets.Layout(width=f"{self._figures_size[0] + 8}px",
                                                             justify_content="center", align_items="center"))

        checks = [self.sky, self.log_radius, self.energy_compensation]
        # the status line keeps one line's height whatever it says: the widget does not jump
        self.status.layout = widgets.Layout(height="22px", overflow="hidden", width=_CONTROL_WIDTH)
        controls = widgets.VBox(
            [header("Material"), self.preset, self.model, self.base_color, *self.sliders.values(),
             header("Light and view"), self.light_theta, self.light_phi, self.view_theta, self.view_phi,
             self.exposure, self.environment, *checks, self.status],
            layout=widgets.Layout(width=_PANEL_WIDTH, min_width=_PANEL_WIDTH, flex="0 0 auto"))
        # two columns of pictures where they fit beside the controls, one where only one does, and
        # below the controls on a narrow page: they wrap, never clip
        column = self._figures_size[0] + 8
        pictures = widgets.Box([cell(self.images[name]) for name in OUTPUTS],
                               layout=widgets.Layout(display="flex", flex_flow="row wrap", align_items="flex-start",
                                                     align_content="flex-start", flex="1 1 auto",
                                                     min_width=f"{column}px", max_width=f"{2 * column}px"))
        self.widget = widgets.Box([controls, pictures],
                                  layout=widgets.Layout(display="flex", flex_flow="row wrap",
                                                        align_items="flex-start", width="100%"))
        self._initial = (material, preset, {control: (control.value, getattr(control, "max", None))
                                            for control in self._controls()
                                            if control not in (self.preset, self.base_color)})
        self._grey_out_unread()
        self.refresh()

    # ------------------------------------------------------------------
    # state

    @staticmethod
    def _default_light() -> tuple[float, float]:
        light = np.asarray(_render.DEFAULT_LIGHT, dtype=np.float64)
        light = light / np.linalg.norm(light)
        theta = math.degrees(math.acos(float(light[2])))
        phi = math.degrees(math.atan2(float(light[1]), float(light[0]))) % 360.0
        return round(theta * 2.0) / 2.0, float(round(phi))

    def _controls(self) -> list[Any]:
        return [*self.sliders.values(), self.base_color, self.model, self.preset, self.light_theta, self.light_phi,
                self.view_theta, self.view_phi, self.exposure, self.sky, self.environment, self.log_radius,
                self.energy_compensation]

    @property
    def material(self) -> Material:
        """The material the sliders show (``base_color`` linear), the parameters the model does
        not read at their defaults (their sliders are greyed out)."""
        return Material(base_color=self._base_color, **self._values(), bright_base_color=True)

    def _values(self) -> dict[str, float]:
        unread = unread_parameters(self.model.value)
        return {name: float(PARAMETERS[name].default) if name in unread else float(s.value)  # type: ignore[arg-type]
                for name, s in self.sliders.items()}

    def _grey_out_unread(self) -> None:
        """The model's controls: the sliders of the parameters it does not read greyed out, the
        energy compensation where it offers none (the thin sheet), and the view from below (θ to
        180°) for the 2015 models."""
        unread = unread_parameters(self.model.value)
        for name, slider in self.sliders.items():
            slider.disabled = name in unread
        self.energy_compensation.disabled = not _models.offers_energy_compensation(self.model.value)
        self.view_theta.max = 180.0 if _models.is_whole_sphere(self.model.value) else 90.0

    def _state(self) -> dict[str, Any]:
        return {
            "material": (self._base_color,) + tuple(self._values().values()),
            "model": self.model.value,
            "light": (float(self.light_theta.value), float(self.light_phi.value)),
            "view": (float(self.view_theta.value), float(self.view_phi.value)),
            "exposure": float(self.exposure.value),
            "sky": bool(self.sky.value),
            "environment": self.environment.value,
            "log": bool(self.log_radius.value),
            "energy_compensation": bool(self.energy_compensation.value)
            and _models.offers_energy_compensation(self.model.value),
        }

    @contextlib.contextmanager
    def hold(self) -> Iterator[Explorer]:
        """Change several controls with one update at the end: ``with explorer.hold(): ...``."""
        self._holding += 1
        try:
            yield self
        finally:
            self._holding -= 1
            if not self._holding:
                self.refresh()

    def refresh(self) -> dict[str, float]:
        """Redraw the pictures whose inputs changed; returns ``{name: seconds}`` of those drawn
        (nothing after :meth:`close`)."""
        if self._closed:
            return {}
        state = self._state()
        material = self.material
        start = time.perf_counter()
        drawn = {}
        for name in OUTPUTS:
            key = _inputs(name, state)
            if self._rendered.get(name) == key:
                continue
            begin = time.perf_counter()
            with self._matplotlib.rc_context(_FONT):
                self.images[name].value = getattr(self, f"_draw_{name}")(material, state)
            self._rendered[name] = key
            drawn[name] = self.timings[name] = time.perf_counter() - begin
        if drawn:
            self.last_update_seconds = time.perf_counter() - start
            self._timing_status = f"{self.last_update_seconds * 1e3:.0f} ms"
            # each picture's time in the tooltip: one line stays short enough for the controls' width
            self._timing_detail = ", ".join(f"{name} {seconds * 1e3:.0f} ms" for name, seconds in drawn.items())
            self._sphere_status()
        return drawn

    def _changed(self, change: Mapping[str, Any]) -> None:
        if self._closed:
            return
        if change["owner"] is self.model:
            with self.hold():  # (a view from below comes back to 90° with a BRDF: one update)
                self._grey_out_unread()
        material_control = change["owner"] is self.base_color or change["owner"] in self.sliders.values()
        if material_control and not self._quiet and self.preset.value != CUSTOM:
            self._quietly(lambda: setattr(self.preset, "value", CUSTOM))
        if not self._holding:
            self.refresh()

    def _quietly(self, action: Callable[[], object]) -> None:
        quiet, self._quiet = self._quiet, True
        try:
            action()
        finally:
            self._quiet = quiet

    def _color_picked(self, change: Mapping[str, Any]) -> None:
        if self._quiet or self._closed:
            return
        try:
            self._base_color = _picked(change["new"])
        except ValueError:  # not a color (yet): keep the last one
            return
        self._changed(change)

    def _preset_chosen(self, change: Mapping[str, Any]) -> None:
        if self._quiet or self._closed or change["new"] == CUSTOM:
            return
        self.set_material(_presets.get(change["new"]), preset=change["new"])

    def reset(self) -> None:
        """Every control back to where the explorer started (one update)."""
        material, preset, controls = self._initial
        with self.hold():
            def restore_ranges() -> None:
                for control, (_, upper) in controls.items():
                    if upper is not None:
                        control.max = upper

            self._quietly(restore_ranges)
            self.set_material(material, preset=preset)
            for control, (value, _) in controls.items():
                if control not in self.sliders.values():
                    control.value = value

    def set_material(self, material: Material | str, *, preset: str | None = None) -> None:
        """Set every material control to ``material`` (a uniform Material or a preset name), one update."""
        material, named = _uniform(material)
        preset = preset or named
        for name, limit in _KERNEL_LIMITS.items():  # what the kernels take: the pictures could not be drawn
            value = np.asarray(getattr(material, name), dtype=np.float64)
            if np.any(value > limit):
                raise ValueError(f"material: {name} = {value.tolist()!r} is beyond {limit:g}, the most the "
                                 "explorer's kernels take")

        def apply() -> None:
            for name, s in self.sliders.items():
                value = float(getattr(material, name))
                if value > s.max:  # an unbounded parameter beyond the slider's range
                    s.max = math.ceil(value)
                s.value = value
            self._base_color = tuple(float(c) for c in material.base_color)
            self.base_color.value = _hex(self._base_color)
            self.preset.value = preset if preset in self.preset.options else CUSTOM

        with self.hold():
            self._quietly(apply)

    # ------------------------------------------------------------------
    # pictures

    # A legend costs as much to draw as the rest of a plot: each one is drawn once, to pixels, and
    # shown as a figure image (cached by its entries).

    def _legend(self, fig: Figure) -> FigureImage:
        return fig.figimage(np.zeros((1, 1, 4)), 0, 0, origin="upper", zorder=10)

    def _legend_pixels(self, entries: tuple[str, ...], ncol: int, frame: bool) -> NDArray[np.float32]:
        key = (entries, ncol, frame)
        if key not in self._legend_cache:
            from matplotlib.lines import Line2D

            fig = self._Figure(figsize=(_FIGSIZE[0], 1.2), dpi=_DPI)
            self._canvas(fig)
            fig.patch.set_alpha(0.0)
            styles: dict[str, dict[str, Any]] = {
                **{name: dict(color=color, lw=1.8 if name == "total" else 1.2, label=name)
                   for name, color in _LOBE_COLORS.items()}, **_KEY_STYLES}
            legend = fig.legend(handles=[Line2D([], [], **styles[name]) for name in entries], loc="center", ncol=ncol,
                                frameon=frame, framealpha=0.85, edgecolor="none", handlelength=1.5,
                                columnspacing=1.0, borderpad=0.3)
            fig.canvas.draw()
            pixels = np.asarray(cast("_AggCanvas", fig.canvas).buffer_rgba())  # the canvas _canvas made
            box = legend.get_window_extent()
            height = pixels.shape[0]
            rows = slice(max(0, int(height - box.y1) - 1), min(height, int(math.ceil(height - box.y0)) + 1))
            columns = slice(max(0, int(box.x0) - 1), int(math.ceil(box.x1)) + 1)
            self._legend_cache[key] = pixels[rows, columns].astype(np.float32) / 255.0
        return self._legend_cache[key]

    def _place_legend(self, image: FigureImage, entries: tuple[str, ...], *, ncol: int, frame: bool, top: float,
                      centre_x: float | None = None, left: float | None = None) -> None:
        pixels = self._legend_pixels(entries, ncol, frame)
        width, height = self._figures_size
        image.set_data(pixels)
        # (the callers give centre_x or left)
        image.ox = (round(centre_x * width - pixels.shape[1] / 2) if centre_x is not None
                    else round(cast(float, left) * width))
        image.oy = round(top * height) - pixels.shape[0]

    def _canvas(self, fig: Figure) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)

    def _savefig(self, name: str) -> bytes:
        # the figure's own Agg canvas and renderer, kept between draws (its text metrics stay cached)
        canvas = cast("_AggCanvas", self._figures[name].canvas)  # the canvas _canvas made
        canvas.draw()
        return _render.png_bytes(np.asarray(canvas.buffer_rgba()))

    def _draw_sphere(self, material: Material, state: Mapping[str, Any]) -> bytes:
        key = tuple(v for k, v in zip(_DEPENDS["sphere"], _inputs("sphere", state)) if k != "exposure")
        if self._sphere["key"] != key:  # an exposure change only tone maps again
            samples = _pass_samples(state)
            self._sphere = {"key": key, "material": material, "state": dict(state), "passes": 1,
                            "samples": samples, "sum": self._render_sphere(material, state, samples, 0) * samples}
            self._schedule_refinement()
        self._sphere["state"]["exposure"] = state["exposure"]  # the passes to come are shown at it
        return self._sphere_png(state["exposure"])

    def _sphere_png(self, exposure: float) -> bytes:
        mean = self._sphere["sum"] / self._sphere["samples"]
        return _render.png_bytes(_rgba(mean, self._inside, 2.0 ** exposure))

    def _render_sphere(self, material: Material, state: Mapping[str, Any], samples: int, seed: int) -> Float32Array:
        light = _direction(*state["light"])
        model = state["model"]
        n = self.resolution
        return _render.render_sphere(material, n, light=light, ambient=0.0 if state["sky"] else _AMBIENT, model=model,
                                     environment=state["environment"] if state["sky"] else None, samples=samples,
                                     seed=seed, energy_compensation=state["energy_compensation"])

    @property
    def sphere_samples(self) -> int:
        """Samples per pixel of the sphere shown: its first pass's, and more as it refines."""
        return int(self._sphere["samples"])

    def refine(self, passes: int = 1) -> int:
        """Render ``passes`` more passes of the sphere into the picture shown (each with its own
        lattice shift, averaged), up to 512 samples per pixel; returns the samples per pixel.
        In a notebook the explorer does this by itself while the controls rest."""
        passes = _validate.integer("passes", passes)
        for _ in range(passes):
            if self._closed or not self._refinable():
                break
            sphere = self._sphere
            samples = _pass_samples(sphere["state"], first=False)
            sphere["sum"] = sphere["sum"] + self._render_sphere(sphere["material"], sphere["state"], samples,
                                                                sphere["passes"]) * samples
            sphere["passes"] += 1
            sphere["samples"] += samples
            self.images["sphere"].value = self._sphere_png(sphere["state"]["exposure"])
            self._sphere_status()
        return self.sphere_samples

    def _refinable(self) -> bool:
        """Whether more passes change the sphere: it samples an environment or light through itself."""
        sphere = self._sphere
        if sphere["key"] is None or sphere["samples"] >= _REFINED_SAMPLES:
            return False
        state = sphere["state"]
        return bool(state["sky"]) or _models.is_whole_sphere(state["model"])

    def _schedule_refinement(self) -> None:
        """In a running event loop (a notebook's kernel), the next pass after a short rest; the
        kernel answers the front end between passes, and a change starts the sphere afresh."""
        if self._refinement is not None:
            self._refinement.cancel()
            self._refinement = None
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:  # no loop (a script, a test): refine() by hand
            return
        if self._refinable():
            self._refinement = loop.call_later(_REFINE_DELAY, self._refine_step)

    def _refine_step(self) -> None:
        self._refinement = None
        if self._closed or self._holding:
            return
        self.refine(1)
        self._schedule_refinement()

    def _sphere_status(self) -> None:
        more = " (refining)" if self._refinable() else ""
        self.status.value = (f'<small style="white-space:nowrap" title="{self._timing_detail}">updated in '
                             f"{self._timing_status} · sphere {self.sphere_samples} samples/px{more}</small>")

    def _build_polar(self, Figure: type[Figure]) -> None:
        fig = Figure(figsize=_FIGSIZE, dpi=_DPI)
        self._canvas(fig)
        # The Axes becomes a square, the half disc (radius: half its side) centred in it: a radius of
        # 135 px, the horizon 75 px above the bottom (room for the legend); the title is a figure text.
        ax = cast("PolarAxes", fig.add_axes(_HALF_DISC_AXES, projection="polar"))
        _upper_half_disc(ax)
        ax.set_thetagrids([-90, -60, -30, 0, 30, 60, 90])
        ax.set_rlabel_position(80)  # near the horizon on the side of wo
        t = np.radians((np.arange(_POLAR_STEPS) + 0.5) * (180.0 / _POLAR_STEPS) - 90.0)  # open: no horizon segment
        lines = {name: ax.plot(t, np.zeros_like(t), color=color, lw=1.8 if name == "total" else 1.2, label=name)[0]
                 for name, color in _LOBE_COLORS.items()}
        lines["wo"] = ax.plot([0, 0], [0, 1], **_KEY_STYLES["wo"])[0]
        lines["wi"] = ax.plot([0, 0], [0, 1], **_KEY_STYLES["wi"])[0]
        title = fig.text(0.5, 0.985, "", ha="center", va="top", fontsize=_FONT["axes.titlesize"])
        self._polar = {"ax": ax, "t": t, "lines": lines, "legend": self._legend(fig), "title": title, "span": 90.0}
        self._figures["polar"] = fig

    def _polar_span(self, span: float) -> Float64Array:
        """The polar plot's angles over the upper half disc (``span`` 90) or the whole circle (180)."""
        ax = self._polar["ax"]
        if self._polar["span"] != span:
            ax.set_position(_HALF_DISC_AXES if span == 90.0 else _DISC_AXES)
            ax.set_thetamin(-span)
            ax.set_thetamax(span)
            if span == 90.0:
                ax.set_thetagrids([-90, -60, -30, 0, 30, 60, 90])
            else:  # the spoke straight down unlabelled: its label would sit on the legend below
                ax.set_thetagrids([-135, -90, -45, 0, 45, 90, 135, 180],
                                  ["-135°", "-90°", "-45°", "0°", "45°", "90°", "135°", ""])
            self._polar["span"] = span
        return np.radians((np.arange(_POLAR_STEPS) + 0.5) * (2.0 * span / _POLAR_STEPS) - span)

    def _draw_polar(self, material: Material, state: Mapping[str, Any]) -> bytes:
        ax, lines = self._polar["ax"], self._polar["lines"]
        t = self._polar_span(180.0 if _models.is_whole_sphere(state["model"]) else 90.0)
        theta_v, phi_v = state["view"]
        azimuth = np.array([math.cos(math.radians(phi_v)), math.sin(math.radians(phi_v))])
        wi = np.empty((t.size, 3))
        wi[:, 0], wi[:, 1], wi[:, 2] = np.sin(t) * azimuth[0], np.sin(t) * azimuth[1], np.cos(t)
        wo = _direction(theta_v, phi_v)
        values = _eval_lobes(material, wi, wo, model=state["model"], energy_compensation=state["energy_compensation"])
        curves = {name: np.asarray(v, dtype=np.float64) @ _LUMINANCE for name, v in zip(_models.LOBE_NAMES, values)}
        curves["total"] = cast("Float64Array", sum(curves.values()))  # (not 0: there are four lobes)
        peak = float(curves["total"].max())
        log = state["log"]
        top = 10.0 ** math.ceil(math.log10(peak)) if peak > 0.0 else 1.0
        floor = top * 10.0 ** -_POLAR_DECADES

        def radius(f: Float64Array) -> Float64Array:
            return np.log10(np.maximum(f, floor) / floor) if log else f

        r_max = float(_POLAR_DECADES) if log else (peak * 1.05 if peak > 0.0 else 1.0)
        shown = []
        for name in _LOBE_COLORS:
            visible = bool(np.any(curves[name] > 0.0)) or name == "total"
            lines[name].set_visible(visible)
            lines[name].set_data(t, radius(curves[name]))
            if visible:
                shown.append(name)
        lines["wo"].set_data([math.radians(theta_v)] * 2, [0.0, r_max])
        light = _direction(*state["light"])
        in_plane = float(light[:2] @ azimuth)
        lines["wi"].set_data([math.atan2(in_plane, float(light[2]))] * 2, [0.0, r_max])
        ax.set_ylim(0.0, r_max)
        if log:
            exponent = round(math.log10(top))
            decades = range(1, _POLAR_DECADES + 1)
            ax.set_yticks(decades, [_power_of_ten(10.0 ** (exponent - _POLAR_DECADES + k)) for k in decades])
        else:
            ax.yaxis.set_major_locator(self._matplotlib.ticker.MaxNLocator(4))
            ax.yaxis.set_major_formatter(self._matplotlib.ticker.ScalarFormatter())
        self._polar["title"].set_text(
            f"f (1/sr, luminance{', log radius' if log else ''}) in the plane of incidence of wo\n"
            f"θv = {theta_v:g}°, φv = {phi_v:g}°; angle: wi from the normal")
        self._place_legend(self._polar["legend"], tuple(shown) + ("wo", "wi"), ncol=4, frame=False,
                           centre_x=0.5, top=0.2)
        return self._savefig("polar")

    def _build_slice(self, Figure: type[Figure]) -> None:
        colors = self._matplotlib.colors
        fig = Figure(figsize=_FIGSIZE, dpi=_DPI)
        self._canvas(fig)
        ax = fig.add_axes((0.13, 0.14, 0.62, 0.74))
        cax = fig.add_axes((0.79, 0.14, 0.035, 0.74))
        _, _, wi, wo = slice_directions(_SLICE_RESOLUTION, 90.0)
        valid = (wi[..., 2] > 0.0) & (wo[..., 2] > 0.0)
        colormap = self._matplotlib.colormaps["inferno"].with_extremes(bad="0.75")
        blank = np.ma.masked_array(np.ones(valid.shape), mask=~valid)
        image = ax.imshow(blank, origin="lower", extent=(0.0, 90.0, 0.0, 90.0), interpolation="nearest",
                          norm=colors.LogNorm(1e-3, 1.0), cmap=colormap, aspect="equal")
        colorbar = fig.colorbar(image, cax=cax)
        colorbar.minorticks_off()
        colorbar.formatter = self._matplotlib.ticker.FuncFormatter(_power_of_ten)
        colorbar.set_label("f, luminance (1/sr)")
        marker = ax.plot([45.0], [45.0], marker="+", ms=11, mew=1.8, color="cyan", ls="none",
                         label="light/view pair")[0]
        ax.set_xlabel("θh (degrees)")
        ax.set_ylabel("θd (degrees)")
        ax.set_xticks([0, 30, 60, 90])
        ax.set_yticks([0, 30, 60, 90])
        self._slice = {"ax": ax, "image": image, "colorbar": colorbar, "marker": marker, "wi": wi, "wo": wo,
                       "valid": valid}
        self._figures["slice"] = fig

    def _draw_slice(self, material: Material, state: Mapping[str, Any]) -> bytes:
        s = self._slice
        f = _eval_lobes(material, s["wi"], s["wo"], model=state["model"],
                        energy_compensation=state["energy_compensation"])
        luminance = np.asarray(f.total(), dtype=np.float64) @ _LUMINANCE
        shown = luminance[s["valid"]]
        top = float(shown.max()) if shown.size and shown.max() > 0.0 else 1.0
        positive = shown[shown > 0.0]
        bottom = max(float(positive.min()) if positive.size else top * 1e-6, top * 1e-6)
        bottom = min(bottom, top * 0.5)
        s["image"].set_data(np.ma.masked_array(np.maximum(luminance, bottom), mask=~s["valid"]))
        s["image"].set_clim(bottom, top)  # the same LogNorm: the colorbar keeps its ticks' style
        wi, wo = _direction(*state["light"]), _direction(*state["view"])
        h = wi + wo
        length = float(np.linalg.norm(h))
        if length > 1e-9 and wi[2] > 0.0 and wo[2] > 0.0:
            h /= length
            theta_h = math.degrees(math.acos(min(1.0, float(h[2]))))
            theta_d = math.degrees(math.acos(min(1.0, float(wi @ h))))
            s["marker"].set_data([theta_h], [theta_d])
            s["marker"].set_visible(True)
            where = f"pair at θh = {theta_h:.0f}°, θd = {theta_d:.0f}° (+)"
        else:
            s["marker"].set_visible(False)
            where = "pair below the horizon"
        s["ax"].set_title(f"BRDF slice at φd = 90°, log luminance\n{where}", pad=4)
        return self._savefig("slice")

    def _build_albedo(self, Figure: type[Figure]) -> None:
        fig = Figure(figsize=_FIGSIZE, dpi=_DPI)
        self._canvas(fig)
        ax = fig.add_axes((0.13, 0.14, 0.83, 0.74))
        lines = {name: ax.plot(_ALBEDO_ANGLES, np.zeros_like(_ALBEDO_ANGLES), color=color,
                               lw=1.8 if name == "total" else 1.2, label=name)[0]
                 for name, color in _LOBE_COLORS.items()}
        lines["view"] = ax.axvline(45.0, **_KEY_STYLES["θv"])
        ax.set_xlim(0.0, 90.0)
        ax.set_xticks([0, 30, 60, 90])
        ax.set_xlabel("θo (degrees)")
        ax.set_ylabel("directional albedo (luminance)")
        ax.grid(True, color="0.9", lw=0.6)
        self._albedo = {"ax": ax, "lines": lines, "bands": {}, "legend": self._legend(fig)}
        self._figures["albedo"] = fig

    def _draw_albedo(self, material: Material, state: Mapping[str, Any]) -> bytes:
        a = self._albedo
        ax, lines = a["ax"], a["lines"]
        sphere = _models.is_whole_sphere(state["model"])
        angles = _ALBEDO_ANGLES_SPHERE if sphere else _ALBEDO_ANGLES
        ax.set_xlim(0.0, 180.0 if sphere else 90.0)
        ax.set_xticks([0, 45, 90, 135, 180] if sphere else [0, 30, 60, 90])
        result = _albedo(material, np.cos(np.radians(angles)), samples=_ALBEDO_SAMPLES, seed=0,
                         model=state["model"], energy_compensation=state["energy_compensation"])
        curves: dict[str, tuple[FloatArray, FloatArray]] = {"total": (result.total, result.total_error)}
        curves.update({name: (value, error) for name, value, error in
                       zip(_models.LOBE_NAMES, result.lobes, result.lobe_errors)})
        for band in a["bands"].values():
            band.remove()
        a["bands"] = {}
        shown, top = [], 1.0
        for name in _LOBE_COLORS:
            mean = np.asarray(curves[name][0], dtype=np.float64) @ _LUMINANCE
            band = 2.0 * (np.asarray(curves[name][1], dtype=np.float64) @ _LUMINANCE)  # an upper bound
            visible = name == "total" or bool(np.any(mean > 0.0))
            lines[name].set_data(angles, mean)
            lines[name].set_visible(visible)
            if visible:
                shown.append(name)
                a["bands"][name] = ax.fill_between(angles, mean - band, mean + band,
                                                   color=_LOBE_COLORS[name], alpha=0.25, lw=0)
                top = max(top, float((mean + band).max()))
        theta_v = state["view"][0]
        lines["view"].set_xdata([theta_v, theta_v])
        ax.set_ylim(0.0, top * 1.05)
        index = int(np.argmin(np.abs(angles - theta_v)))
        total_at = float(np.asarray(result.total[index]) @ _LUMINANCE)
        ax.set_title(f"directional albedo, ±2 s.e. ({_ALBEDO_SAMPLES} samples)\n"
                     f"E({angles[index]:g}°) = {total_at:.3f}", pad=4)
        self._place_legend(a["legend"], tuple(shown) + ("θv",), ncol=3, frame=True, left=0.135, top=0.875)
        return self._savefig("albedo")

    # ------------------------------------------------------------------

    def write_pngs(self, prefix: str) -> dict[str, str]:
        """Write the four pictures to ``{prefix}{name}.png``; returns ``{name: path}``."""
        paths = {}
        for name in OUTPUTS:
            paths[name] = f"{prefix}{name}.png"
            with open(paths[name], "wb") as f:
                f.write(self.images[name].value)
        return paths

    def close(self) -> None:
        """Close the widgets (and drop the figures). The explorer is inert afterwards: changes to
        its controls are ignored and :meth:`refresh` draws nothing. Closing twice does nothing more."""
        if self._closed:
            return
        self._closed = True
        if self._refinement is not None:
            self._refinement.cancel()
            self._refinement = None
        for control in self._controls():
            handler = (self._preset_chosen if control is self.preset else
                       self._color_picked if control is self.base_color else self._changed)
            control.unobserve(handler, names="value")

        def close(widget: Any) -> None:
            for child in getattr(widget, "children", ()):
                close(child)
            widget.close()

        close(self.widget)
        self._figures.clear()

    def _repr_mimebundle_(self, **kwargs: Any) -> dict[str, Any] | None:
        """The live widget, and beside it what a page without the widget's JavaScript shows
        (nbconvert's HTML, GitHub, any static viewer): the four pictures as PNG in HTML, the
        sphere as ``image/png`` and a text summary."""
        bundle = dict(self.widget._repr_mimebundle_(**kwargs) or {})
        pictures = "".join(f'<img alt="{name}" style="margin:2px" src="data:image/png;base64,'
                           f'{base64.b64encode(self.images[name].value).decode()}"/>' for name in OUTPUTS)
        bundle["text/html"] = f'<div style="display:flex;flex-wrap:wrap;align-items:center">{pictures}</div>'
        bundle["image/png"] = base64.b64encode(self.images["sphere"].value).decode()
        bundle["text/plain"] = f"{self!r}\n(the pictures: {', '.join(OUTPUTS)}; run the notebook for the controls)"
        return bundle

    def __repr__(self) -> str:
        return f"Explorer({self.material!r}, model={self.model.value!r}, resolution={self.resolution})"


def explorer(material: Material | str | None = None, *, model: Model = "disney2014", resolution: int = 192) -> Explorer:
    """An interactive BRDF explorer for Jupyter (module :mod:`principled_brdf.explorer_app`).

    ``material``: the starting material (a uniform Material or a preset name;
    default ``pb.Material()``, the BRDF Explorer's defaults), ``model``:
    ``"disney2014"`` or ``"disney2012"``, ``resolution``: the sphere's size
    in pixels. Returns an :class:`Explorer`, which displays as its widget;
    ``explorer.sliders``, ``explorer.images`` etc. reach its parts. Needs
    ipywidgets and matplotlib (``ImportError`` naming ``pip install
    ipywidgets`` otherwise).
    """
    return Explorer(material, model=model, resolution=resolution)
