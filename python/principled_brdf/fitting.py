"""Fitting the model to measured values of f (docs/fitting.md).

Least squares on residuals between the model and the measurements at given
direction pairs, with the analytic derivatives of the model (finite
differences through a float32 kernel take steps that vanish in its rounding,
and stop at the start point). The default method solves every problem of a
batch together (:mod:`principled_brdf._solver`: one pass of the kernels per
iteration, reduced per problem to the normal equations); ``method="scipy"``
solves one problem at a time by ``scipy.optimize.least_squares``
(trust-region reflective) with :func:`principled_brdf.eval_grad`'s Jacobian.
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
import typing

from collections.abc import Mapping as _Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _gradient, _inert, _models, _solver, _validate, reference
from ._batch import eval
from ._derivatives import eval_grad
from ._gradient import GRADIENT_NAMES_2015
from ._loss_scale import log_scale, log_scales
from .fit_pictures import DEFAULT_ENVIRONMENTS
from .fit_pictures import Comparison
from .fit_pictures import compare as _compare
from .material import PARAMETERS, Material

if TYPE_CHECKING:
    from collections.abc import Callable, Iterator, Mapping, Sequence
    from typing import Literal, SupportsFloat, SupportsIndex

    from .measured import MerlBRDF

    from numpy.typing import NDArray

    from ._typing import Float64Array, Model, RealArrayLike

    # fitted slots, costs, iterations, success, messages, residuals and the
    # parameters set back to their start (module _inert): per problem
    _FitArrays = tuple[Float64Array, Float64Array, NDArray[np.int64], NDArray[np.bool_], list[str], Float64Array,
                       list[list[str]]]

__all__ = ["fit", "FitResult", "FIT_BOUNDS", "LOSSES", "METHODS", "LOBE_GAIN", "OPTIONAL_LOBES"]

# Default bounds for fitting: the domains, with the unbounded parameters held
# to [0, 1] as the BRDF Explorer's sliders are (pass bounds= to widen them).
FIT_BOUNDS = {name: (max(info.lower, 0.0), info.upper if math.isfinite(info.upper) else 1.0)
              for name, info in PARAMETERS.items()}
LOSSES = ("scaled_log", "log", "relative", "linear")
METHODS = ("batched", "scipy")
# Without init=, the losses named here also fit from a second start and keep, per problem, the
# result of the lower cost (docs/fitting.md#starts): from the default dielectric start the
# relative loss settles on a dark dielectric of a rough conductor's data (Beckmann copper,
# α 0.5: metallic 0, 91 % of the albedo missing) where a metal start reaches a lower cost.
_SECOND_STARTS: dict[str, dict[str, Any]] = {"relative": {"metallic": 1.0}}
#: The lobes model selection may hold off (docs/fitting.md#lobes-the-data-do-not-need), each with
#: the parameter only it reads (set back to its start when the lobe is held off) and the largest
#: value at which it is tried: metallic as a dielectric's metallic share (above a half the fit is
#: a metal, and a dielectric in its place is another material, not the same one without a lobe).
OPTIONAL_LOBES: dict[str, tuple[str | None, float]] = {
    "clearcoat": ("clearcoat_gloss", math.inf), "sheen": ("sheen_tint", math.inf), "metallic": (None, 0.5)}
#: A lobe a fit turned on is kept where it divides the cost by more than this.
LOBE_GAIN = 2.0
# The batched solver stops when a taken step lowers the cost by less than this
# fraction: the float32 kernels' cost is exact to about 1e-7 of itself.
_FTOL = {"float32": 1e-7, "float64": 1e-10}


def _batch_problems(pairs: int) -> int:
    """Problems the batched solver takes together: about 4 million samples' worth."""
    return max(1, (1 << 22) // max(1, pairs))
# The "relative" loss divides by max(m, _RELATIVE_FLOOR_FRACTION * max m, _RELATIVE_FLOOR) (1/sr):
# the absolute floor keeps a black problem (every m = 0) finite; it then fits f towards 0.
_RELATIVE_FLOOR_FRACTION = 1e-3
_RELATIVE_FLOOR = 1e-9
_MAX_WEIGHT = 1e30  # weights times squared residuals (at most ~1e95) stay finite
_NO_DATA = "no data: every sample of this problem is missing (NaN); the result is the start"
_ANISOTROPY_HELD = ("anisotropic held at its start (default 0): the pairs' half vectors all lie in one plane "
                    "through the normal, which cannot determine it; name it in fit= to fit it anyway")
_NOTHING_FITTED = "nothing to fit: every parameter in fit is held by equal bounds; the result is the start"


@dataclass(frozen=True)
class FitResult:
    """What :func:`fit` returns; for a batch of problems every field has a leading batch axis."""

    # (a single problem: cost, iterations and success are numpy scalars, message a str)
    material: Material  # the fitted material (per element along the batch axis for a batch)
    slots: Float64Array  # (..., P) its values in the model's derivative slots (eval_grad's names: 13, 16 for 2015)
    cost: np.float64 | Float64Array  # 0.5 * sum of squared (weighted) residuals, per problem
    residuals: Float64Array  # (..., N, 3) unweighted, at the fitted material; NaN where measured is NaN
    iterations: np.int64 | NDArray[np.int64]  # evaluations of the derivatives, per problem
    success: np.bool_ | NDArray[np.bool_]  # converged, per problem (False: no data, or max_iterations reached)
    message: str | tuple[str, ...]  # why the solver stopped, per problem, or why it was not fitted
    names: tuple[str, ...]  # the fitted parameters (slot names, base_color as three)
    notes: tuple[str, ...] = ()  # what the fit decided by itself (e.g. a parameter the data cannot determine)
    model: str = "disney2014"  # the model fitted

    def compare(self, data: MerlBRDF | Callable[..., Any], *, texel: SupportsIndex | tuple[SupportsIndex, ...] | None = None,
                environments: Sequence[str] = DEFAULT_ENVIRONMENTS, resolution: int = 128, samples: int = 256,
                seed: int = 0) -> Comparison:
        """The data and the fit rendered side by side (:func:`~principled_brdf.fit_pictures.compare`):
        ``data`` a MerlBRDF or a callable ``f(wi, wo)`` (for a batched fit, the data of ``texel``,
        the index of the problem to show along the batch axes); under each of ``environments``
        (the studio and the outdoor by default), ``samples`` per pixel. ``.figure()`` of the
        result draws them with their difference and the image error."""
        if texel is None and self.material.shape != ():
            raise ValueError(f"texel: a batched fit (batch shape {self.material.shape}) shows one problem: give its index")
        material = self.material if texel is None else self.material[texel]
        return _compare(material, typing.cast("Model", self.model), data, environments=environments,
                        resolution=resolution, samples=samples, seed=seed)

    def summary(self) -> str:
        rows = np.atleast_2d(self.slots)
        width = rows.shape[1]
        lines = []
        for row, values in enumerate(rows):
            converged = bool(np.atleast_1d(self.success)[row])
            head = f"problem {row}: " if len(rows) > 1 else ""
            lines.append(f"{head}{'converged' if converged else 'NOT converged'} after "
                         f"{int(np.atleast_1d(self.iterations)[row])} iterations, "
                         f"cost {float(np.atleast_1d(self.cost)[row]):.6g}")
            shown = []
            for name, info in _parameters_in(width).items():
                v = values[info.first_slot:info.first_slot + info.slots]
                shown.append(f"{name}=({', '.join(f'{c:.4g}' for c in v)})" if info.slots == 3 else f"{name}={v[0]:.4g}")
            lines.append("  " + ", ".join(shown))
        lines.append("  fitted: " + ", ".join(self.names))
        lines += [f"  note: {note}" for note in self.notes]
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.summary()


def _bound_pair(name: str, pair: object) -> tuple[float, float]:
    """``(lower, upper)`` of ``bounds[name]``: two real numbers, not NaN."""
    where = f"bounds[{name!r}]"
    if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or not hasattr(pair, "__getitem__"):
        raise TypeError(f"{where}: expected a (lower, upper) pair of numbers, got {pair!r}")
    if len(pair) != 2:
        raise ValueError(f"{where}: expected a (lower, upper) pair of numbers, got {len(pair)} values")
    values = []
    for value in (pair[0], pair[1]):
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise TypeError(f"{where}: expected a (lower, upper) pair of numbers, got {pair!r}")
        values.append(float(value))
    if any(math.isnan(v) for v in values):
        raise ValueError(f"{where}: ({values[0]}, {values[1]}) is not an interval (NaN)")
    return values[0], values[1]


def _domain(name: str, model: Model) -> tuple[float, float]:
    """A parameter's domain under ``model``: the 2015 models turn specular into an index of
    refraction, which MAX_IOR bounds."""
    info = PARAMETERS[name]
    limit = _models.max_specular(model)
    if name == "specular" and limit < math.inf:
        return info.lower, limit
    return info.lower, info.upper


def _slot_bounds(
    bounds: Mapping[str, tuple[SupportsFloat, SupportsFloat]] | None, model: Model, width: int,
) -> tuple[Float64Array, Float64Array]:
    """(lower, upper) of the ``width`` slots of ``model``'s derivatives."""
    merged = dict(FIT_BOUNDS)
    if bounds is not None and not isinstance(bounds, _Mapping):
        raise TypeError(f"bounds: expected a mapping {{name: (lower, upper)}}, got {type(bounds).__name__}")
    for name, pair in (bounds or {}).items():
        if name not in FIT_BOUNDS:
            raise ValueError(f"bounds: unknown parameter {name!r}")
        low, high = _bound_pair(name, pair)
        domain = _domain(name, model)
        if not (domain[0] <= low <= high <= domain[1]):
            raise ValueError(f"bounds[{name!r}]: ({low}, {high}) is not an interval inside its domain "
                             f"[{domain[0]}, {domain[1]}]" + (f" under model {model!r}" if name == "specular" else ""))
        merged[name] = (low, high)
    lower = np.empty(width)
    upper = np.empty(width)
    for name, info in _parameters_in(width).items():
        lower[info.first_slot:info.first_slot + info.slots] = merged[name][0]
        upper[info.first_slot:info.first_slot + info.slots] = merged[name][1]
    return lower, upper


def _parameters_in(width: int) -> dict[str, Any]:
    """The parameters held by the first ``width`` slots (13: the 2012 and 2014 models', 16: all)."""
    return {name: info for name, info in PARAMETERS.items() if info.first_slot < width}


def _fitted_slots(fit: object, model: Model, width: int) -> list[int]:
    """The slots ``fit`` names (default: every parameter ``model`` reads), in the table's order."""
    unread = _models.unread_parameters(model)
    owners = [name for name, info in _parameters_in(len(GRADIENT_NAMES_2015)).items() for _ in range(info.slots)]
    if fit is None:
        return [k for k in range(width) if owners[k] not in unread]
    requested = _gradient.columns(fit, "fit", names=GRADIENT_NAMES_2015)
    for k in requested:
        if owners[k] in unread:
            hint = " (fit flatness instead)" if owners[k] == "subsurface" else ""
            raise ValueError(f"fit: model {model!r} does not read {owners[k]!r}{hint}")
    return requested


def _initial_slots(init: Material | dict[str, Any] | None, model: Model, width: int) -> Float64Array:
    if init is None:
        init = Material()
    if isinstance(init, dict):
        init = Material(**init)
    if not isinstance(init, Material) or not init.is_uniform:
        raise TypeError("init: expected a uniform principled_brdf.Material or a dict of its parameters")
    init.require_read_by(model)
    return np.asarray(init.packed(()), dtype=np.float64).reshape(-1)[:width]


def _material_of(slot_values: Float64Array) -> Material:
    """A material from slot values ``(..., P)`` (13 or 16 slots), uniform when one row."""
    values: dict[str, Any] = {}  # Material's keywords
    for name, info in _parameters_in(slot_values.shape[-1]).items():
        block = slot_values[..., info.first_slot:info.first_slot + info.slots]
        values[name] = block if info.slots == 3 else block[..., 0]
    return Material(**values)


def _cosine_factors(wi: NDArray[Any], cosine: bool, model: Model) -> Float64Array:
    """The losses' c per pair: cos θl clamped to 0 below the surface (where a BRDF is 0), |cos θl|
    for the 2015 BSDFs (as eval's cosine=True), or 1 without ``cosine``."""
    if not cosine:
        return np.ones(wi.shape[:-1])
    return np.abs(wi[..., 2]) if _models.is_whole_sphere(model) else np.maximum(wi[..., 2], 0.0)


def _residual_and_jacobian(value: Float64Array, jacobian: Float64Array, measured: Float64Array,
                           cos_theta: Float64Array, loss: str, scale: Float64Array,
                           level: float) -> tuple[Float64Array, Float64Array]:
    """Residuals r (n, 3) and dr/dslot (n, 3, P) for one problem; ``scale`` the relative
    loss's divisors (n, 3), ``level`` the log losses' s (1/sr)."""
    if loss in ("log", "scaled_log"):
        model = value * cos_theta[:, None] / level
        residual = np.log1p(model) - np.log1p(measured * cos_theta[:, None] / level)
        derivative = (cos_theta[:, None] / (level * (1.0 + model)))[..., None] * jacobian
    elif loss == "relative":
        residual = (value - measured) / scale
        derivative = jacobian / scale[..., None]
    else:
        residual = (value - measured) * cos_theta[:, None]
        derivative = jacobian * cos_theta[:, None, None]
    return residual, derivative


# Concurrent fits share one BLAS limit: the first to enter sets it, the last to leave restores
# what was there before the first (a limit per call would restore the other call's 1 at the end).
_blas_lock = threading.Lock()
_blas_users = 0
_blas_limiter: Any = None
_blas_original: dict[str, int] = {}
_BLAS_RESTORE_TRIES = 5


@contextlib.contextmanager
def _one_blas_thread() -> Iterator[None]:
    """BLAS on one thread (threadpoolctl, when installed): each trust-region step takes
    the SVD of the tall (N, P) Jacobian, which threads slow down (a 20,000-pair fit on
    two cores: 12.6 s with OpenBLAS's threads, 4.1 s with one). Calls that overlap (from
    several threads) share the limit, and the last one out restores the previous limits."""
    global _blas_users, _blas_limiter, _blas_original
    try:
        from threadpoolctl import threadpool_limits  # type: ignore[import-untyped]  # it ships no type hints
    except ImportError:  # pragma: no cover - in the fit and test extras
        yield
        return
    with _blas_lock:
        if _blas_users == 0:
            _blas_original = _blas_thread_counts()
            _blas_limiter = threadpool_limits(1, user_api="blas")
        _blas_users += 1
    try:
        yield
    finally:
        with _blas_lock:
            _blas_users -= 1
            if _blas_users == 0:
                limiter, _blas_limiter = _blas_limiter, None
                _restore_blas_threads(limiter, _blas_original)


def _blas_thread_counts() -> dict[str, int]:
    from threadpoolctl import threadpool_info

    return {info["filepath"]: info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas"}


def _restore_blas_threads(limiter: Any, original: dict[str, int]) -> None:
    """Undo a threadpoolctl limit, checked against the counts before it: OpenBLAS
    (0.3.30 and 0.3.31 seen) now and then keeps its count of 1 when it is set back
    right after BLAS calls of two threads, then takes the same setting a few
    milliseconds later. Left unchecked, BLAS stayed on one thread for the rest of
    the process."""
    for attempt in range(_BLAS_RESTORE_TRIES):
        if attempt:
            time.sleep(1e-3 * 2**attempt)
        limiter.restore_original_limits()
        now = _blas_thread_counts()
        if all(now.get(path) == count for path, count in original.items()):
            return


def fit(wi: RealArrayLike, wo: RealArrayLike, measured: RealArrayLike, *,
        init: Material | dict[str, Any] | None = None, fit: str | list[str] | tuple[str, ...] | None = None,
        loss: Literal["scaled_log", "log", "relative", "linear"] = "scaled_log", weights: RealArrayLike | None = None,
        bounds: Mapping[str, tuple[SupportsFloat, SupportsFloat]] | None = None, model: Model = "disney2014",
        cosine: bool = True, precision: Literal["float32", "float64"] = "float32",
        max_iterations: SupportsIndex = 200, method: Literal["batched", "scipy"] = "batched",
        threads: SupportsIndex | None = None, select_lobes: bool = True) -> FitResult:
    """The material that best matches ``measured`` values of f (1/sr) at the pairs (wi, wo).

    ``wi``, ``wo``: unit directions ``(N, 3)``; ``measured``: ``(N, 3)``, or
    ``(B, N, 3)`` for B independent problems (one material per row, e.g. the
    texels of a texture; ``wi``, ``wo`` may then be ``(B, N, 3)`` too). NaN
    marks a missing sample; values beyond float32's range are refused (no
    material reaches them). ``init``: the start (a uniform Material or a dict;
    default ``Material()``, and for the ``"relative"`` loss a metal as well,
    the lower cost kept per problem), which also holds the parameters not in
    ``fit`` (names; default every parameter ``model`` reads, ``base_color``
    as three channels, except that ``anisotropic`` is held at its start when
    the pairs cannot determine it: every half vector in one plane through the
    normal, as a MERL table's pairs; the result's ``notes`` and ``summary()``
    say so). ``model``: any of eval's, the same for every method; the 2015
    models fit ``spec_trans`` and ``flatness`` too (and ``diff_trans`` for
    ``"disney2015_thin"``), and ``slots`` then holds 16 slots (eval_grad's
    columns for the model).
    ``loss``: ``"scaled_log"`` (the default: ``log(1 + f c / s) - log(1 + m c / s)``,
    c = cos θl (``|cos θl|`` for the 2015 models) if ``cosine`` else 1, s the
    median of the problem's m c but at least a tenth of their mean:
    logarithmic over the specular peak's decades, the same for a bright and a
    dim material), ``"log"`` (the same with s = 1/sr),
    ``"relative"`` (``(f - m) / max(m, 1e-3 max m, 1e-9)``, max m over the
    problem's samples: the floors keep zero measurements finite, and a black
    problem, every m = 0, fits f towards 0; it fits metals too dark:
    docs/fitting.md#losses) or ``"linear"`` (``(f - m) c``).
    ``weights`` ``(N,)`` or ``(B, N)`` (0 to 1e30) scale each pair's squared
    residuals. ``bounds``: ``{name: (lower, upper)}`` over :data:`FIT_BOUNDS`
    (the domains, with the unbounded parameters held to [0, 1]); a parameter
    whose bounds are equal is held at that value (it is not fitted, nor listed
    in ``names``). ``precision``: ``"float32"`` (the SIMD kernels) or
    ``"float64"`` (the reference). ``max_iterations``: an integer >= 1, the
    most evaluations of the model per problem.

    ``select_lobes`` (default True): each of ``clearcoat``, ``sheen`` and
    ``metallic`` (up to 0.5: a dielectric's metallic share) that the fit
    turns on is fitted again held at 0, and stays
    off where it does not divide the cost by more than :data:`LOBE_GAIN` (2):
    a lobe imitating another model's shape (a clearcoat for a Beckmann tail)
    lowers the cost by tens of percent, one the data need by far more
    (docs/fitting.md#lobes-the-data-do-not-need); ``notes`` and ``summary()``
    name the lobes held off and the factor.

    ``method``: ``"batched"`` (default) solves all problems together by
    Levenberg-Marquardt with the bounds (docs/fitting.md): each iteration
    evaluates every unfinished problem in one pass of the kernels, reduced per
    problem to its normal equations in C++; a problem's result is the same
    bits whichever problems share its batch and whatever ``threads`` (default
    all cores). ``"scipy"``: ``scipy.optimize.least_squares`` (trust-region
    reflective) one problem after another.

    A problem without data (every sample NaN) is not fitted and does not stop
    the others: its result is the start (``init`` clipped to ``bounds``), cost
    0.0 (the sum over no samples), iterations 0, success False and a message
    starting ``"no data"``; its residuals are NaN. When equal bounds hold
    every parameter of ``fit``, each problem's result is the start, evaluated
    (cost and residuals), with iterations 0 and success True.
    """
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"method: expected one of {', '.join(METHODS)}, got {method!r}")
    thread_count = 0  # all cores
    if threads is not None:
        thread_count = _validate.integer("threads", threads)
        if not 1 <= thread_count <= 2**31 - 1:
            raise ValueError(f"threads: expected an integer from 1 to 2**31 - 1, got {thread_count}")
    if not isinstance(loss, str) or loss not in LOSSES:
        raise ValueError(f"loss: expected one of {', '.join(LOSSES)}, got {loss!r}")
    if not isinstance(precision, str) or precision not in ("float32", "float64"):
        raise ValueError(f"precision: expected 'float32' or 'float64', got {precision!r}")
    cosine = _validate.flag("cosine", cosine)
    select_lobes = _validate.flag("select_lobes", select_lobes)
    max_iterations = _validate.integer("max_iterations", max_iterations)
    if max_iterations < 1:
        raise ValueError(f"max_iterations: expected an integer >= 1, got {max_iterations}")
    measured = np.asarray(_validate.as_real_array("measured", measured), dtype=np.float64)
    if measured.ndim not in (2, 3) or measured.shape[-1] != 3:
        raise ValueError(f"measured: expected (N, 3) or (B, N, 3) values of f, got shape {measured.shape}")
    finite_or_missing = np.isfinite(measured) | np.isnan(measured)
    if not finite_or_missing.all() or np.any(measured < 0):
        raise ValueError("measured: values must be finite and >= 0 (NaN marks a missing sample)")
    huge = measured > _validate.FLOAT32_MAX  # (NaN is not)
    if huge.any():
        i = _validate.first_true(huge)
        raise ValueError(f"{_validate.element_name('measured', i, measured.shape)}: {float(measured.ravel()[i])!r} "
                         f"is beyond {_validate.FLOAT32_MAX:.7g}, the most the model reaches")
    batched = measured.ndim == 3
    problems = measured if batched else measured[None]
    wi = np.asarray(_validate.directions("wi", wi), dtype=np.float64)
    wo = np.asarray(_validate.directions("wo", wo), dtype=np.float64)
    count, n = problems.shape[:2]
    for w in (wi, wo):
        if w.shape not in ((n, 3), (count, n, 3)):
            raise ValueError(f"wi, wo: expected (N, 3) or (B, N, 3) with B, N = {count}, {n}, got {wi.shape} and {wo.shape}")
    wi_rows = np.broadcast_to(wi, (count, n, 3))
    wo_rows = np.broadcast_to(wo, (count, n, 3))
    if weights is not None:
        weights = np.asarray(_validate.as_real_array("weights", weights), dtype=np.float64)
        allowed = ((n,), (count, n)) if batched else ((n,),)
        if weights.shape not in allowed:
            raise ValueError(f"weights: expected shape {' or '.join(str(a) for a in allowed)} (one per pair), "
                             f"got {weights.shape}")
        bad = ~((weights >= 0.0) & (weights <= _MAX_WEIGHT))
        if bad.any():
            i = _validate.first_true(bad)
            raise ValueError(f"{_validate.element_name('weights', i, weights.shape)}: {float(weights.ravel()[i])!r} "
                             f"is not a weight (expected finite values from 0 to {_MAX_WEIGHT:g})")
        weights = np.broadcast_to(weights, (count, n))
    _validate.model_index(model)  # eval_grad takes the name
    names = _gradient.gradient_names(model)
    requested = _fitted_slots(fit, model, len(names))
    notes: list[str] = []
    anisotropic = names.index("anisotropic")
    if fit is None and not _determines_anisotropy(wi, wo):
        requested.remove(anisotropic)
        notes.append(_ANISOTROPY_HELD)
    lower, upper = _slot_bounds(bounds, model, len(names))
    starts = [_initial_slots(init, model, len(names))]
    if init is None and loss in _SECOND_STARTS:
        starts.append(_initial_slots(_SECOND_STARTS[loss], model, len(names)))
    for start in starts:
        start[requested] = np.clip(start[requested], lower[requested], upper[requested])
    slots = [k for k in requested if lower[k] < upper[k]]  # equal bounds hold a parameter (clipped to it above)

    def solve(start: Float64Array, slots: list[int], lower: Float64Array, upper: Float64Array,
              rows: NDArray[np.int64] | None = None) -> _FitArrays:
        """The fit of the problems ``rows`` (default all) from ``start`` ``(P,)`` or one per row."""
        chosen = np.arange(count) if rows is None else rows
        if method == "scipy":
            return _fit_scipy(wi_rows[chosen], wo_rows[chosen], problems[chosen],
                              None if weights is None else weights[chosen], start, lower, upper, slots, loss, cosine,
                              model, precision, max_iterations)
        if wi.ndim == wo.ndim:
            pair_wi, pair_wo = (wi, wo) if wi.ndim == 2 else (wi[chosen], wo[chosen])
        else:  # one of them per problem: both
            pair_wi, pair_wo = np.ascontiguousarray(wi_rows[chosen]), np.ascontiguousarray(wo_rows[chosen])
        # a few million samples at a time: the solver's arrays stay small whatever the texture
        # (a problem's result does not depend on the problems solved with it)
        parts = []
        for begin in range(0, max(len(chosen), 1), _batch_problems(n)):
            part = slice(begin, min(len(chosen), begin + _batch_problems(n)))
            parts.append(_fit_batched(pair_wi[part] if pair_wi.ndim == 3 else pair_wi,
                                      pair_wo[part] if pair_wo.ndim == 3 else pair_wo, problems[chosen[part]],
                                      None if weights is None else weights[chosen[part]],
                                      start if start.ndim == 1 else start[part], lower, upper, slots, loss,
                                      cosine, model, precision, max_iterations, thread_count))
        return _joined(parts)

    fits = _lowest_cost([solve(s, slots, lower, upper) for s in starts])
    if select_lobes:
        has_data = ~np.all(np.isnan(problems), axis=(1, 2))
        fits, held = _select_lobes(fits, solve, starts[0], slots, lower, upper, names, has_data)
        notes += _held_notes(held, count)
    fitted, costs, iterations, success, messages, residuals_out, reset_names = fits
    if (note := _inert.note(reset_names, count)) is not None:
        notes.append(note)

    take: Callable[[NDArray[Any]], Any] = (lambda a: a) if batched else (lambda a: a[0])
    return FitResult(material=_material_of(fitted if batched else fitted[0]), slots=take(fitted), cost=take(costs),
                     residuals=take(residuals_out), iterations=take(iterations), success=take(success),
                     message=tuple(messages) if batched else messages[0], names=tuple(names[k] for k in slots),
                     notes=tuple(notes), model=model)


def _select_lobes(fits: _FitArrays, solve: Callable[..., _FitArrays], start: Float64Array, slots: list[int],
                  lower: Float64Array, upper: Float64Array,
                  names: Sequence[str],
                  has_data: NDArray[np.bool_]) -> tuple[_FitArrays, dict[str, list[tuple[int, float]]]]:
    """Model selection (docs/fitting.md#lobes-the-data-do-not-need): each of OPTIONAL_LOBES that
    a problem's fit turned on (up to its largest value) is fitted again held at 0, from that fit (the parameters it
    alone reads back at their start); the lobe stays off where that costs less than
    LOBE_GAIN times the cost with it. Returns the fits and, per lobe held off, the problems
    and their cost ratios."""
    fitted, costs, iterations, success, messages, residuals, reset_names = fits
    fitted, costs, iterations, success = fitted.copy(), costs.copy(), iterations.copy(), success.copy()
    messages, residuals, reset_names = list(messages), residuals.copy(), list(reset_names)
    held: dict[str, list[tuple[int, float]]] = {}
    held_by_row: list[tuple[int, ...]] = [()] * len(fitted)  # the slots held at 0 so far, per problem
    for lobe, (follower, largest) in OPTIONAL_LOBES.items():
        k = names.index(lobe)
        if k not in slots:
            continue
        # (a lobe without effect at the fit, set back to its start by module _inert, is no candidate)
        candidates = [row for row in np.flatnonzero((fitted[:, k] > 0.0) & (fitted[:, k] <= largest) & has_data)
                      if lobe not in reset_names[row]]
        # problems with the same lobes held off so far are fitted together, with those held too
        for already in sorted({held_by_row[row] for row in candidates}):
            rows = np.array([row for row in candidates if held_by_row[row] == already], dtype=np.int64)
            zero = already + (k,)
            without = fitted[rows].copy()
            without[:, k] = 0.0
            if follower is not None:
                without[:, names.index(follower)] = start[names.index(follower)]
            held_lower, held_upper = lower.copy(), upper.copy()
            held_lower[list(zero)] = held_upper[list(zero)] = 0.0
            other = solve(without, [j for j in slots if j not in zero], held_lower, held_upper, rows)
            ratio = other[1] / np.maximum(costs[rows], np.finfo(np.float64).tiny)
            for j in np.flatnonzero(other[1] <= LOBE_GAIN * costs[rows]):
                row = rows[j]
                fitted[row], costs[row], success[row] = other[0][j], other[1][j], other[3][j]
                iterations[row] += other[2][j]
                messages[row], residuals[row], reset_names[row] = other[4][j], other[5][j], other[6][j]
                held_by_row[row] = zero
                held.setdefault(lobe, []).append((int(row), float(ratio[j])))
    return (fitted, costs, iterations, success, messages, residuals, reset_names), held


def _held_notes(held: dict[str, list[tuple[int, float]]], count: int) -> list[str]:
    """The result's notes on the lobes model selection held off."""
    notes = []
    for lobe, rows in held.items():
        worst = max(ratio for _, ratio in rows)
        where = "" if count == 1 else f" in {len(rows)} of {count} problems"
        notes.append(f"{lobe} held off{where}: the fit without it costs at most {worst:.3g} times the fit with it "
                     f"(a lobe is kept where that is more than {LOBE_GAIN:g}); select_lobes=False keeps it")
    return notes

def _joined(parts: list[_FitArrays]) -> _FitArrays:
    """The results of consecutive parts of a batch as one."""
    return (np.concatenate([part[0] for part in parts]), np.concatenate([part[1] for part in parts]),
            np.concatenate([part[2] for part in parts]), np.concatenate([part[3] for part in parts]),
            [message for part in parts for message in part[4]], np.concatenate([part[5] for part in parts]),
            [reset for part in parts for reset in part[6]])


def _lowest_cost(results: list[_FitArrays]) -> _FitArrays:
    """Per problem, the result (of fits from several starts) of the lowest cost, the first of equal ones."""
    best = results[0]
    for other in results[1:]:
        better = other[1] < best[1]
        pick = [other if b else best for b in better]
        best = (np.where(better[:, None], other[0], best[0]), np.where(better, other[1], best[1]),
                np.where(better, other[2], best[2]), np.where(better, other[3], best[3]),
                [chosen[4][row] for row, chosen in enumerate(pick)], np.where(better[:, None, None], other[5], best[5]),
                [chosen[6][row] for row, chosen in enumerate(pick)])
    return best


def _fit_scipy(wi_rows: NDArray[Any], wo_rows: NDArray[Any], problems: NDArray[Any], weights: Float64Array | None,
               start: Float64Array, lower: Float64Array, upper: Float64Array, slots: list[int], loss: str,
               cosine: bool, model: Model, precision: str, max_iterations: int) -> _FitArrays:
    """One problem after another by scipy's trust-region reflective least squares.

    It solves for u = 1 + (x - lower) / span, in [1, 2], rather than x: scipy's trust region
    starts at the radius of its (scaled) start, which for parameters that all start on their
    lower bound 0 (clearcoat, sheen; scipy first moves them 1e-10 inside) is about 1e-10. No
    float32 evaluation resolves a step that small, and it stopped there at once; u's first
    radius is the size of the box."""
    try:
        from scipy.optimize import least_squares
    except ImportError as error:  # pragma: no cover - scipy is in the test and fit extras
        raise ImportError("pb.fit(method='scipy') needs scipy: pip install 'principled-brdf[fit]'") from error
    count = problems.shape[0]
    fitted = np.empty((count, start.shape[-1]))
    start_rows = np.broadcast_to(start, fitted.shape)  # one start, or one per problem
    costs, iterations, success, messages = np.empty(count), np.empty(count, np.int64), np.empty(count, bool), []
    residuals_out = np.full(problems.shape, np.nan)
    reset_names: list[list[str]] = [[] for _ in range(count)]  # per problem, the parameters set back to their start
    dtype = np.float32 if precision == "float32" else np.float64
    low, span = lower[slots], upper[slots] - lower[slots]

    def x_of(u: Float64Array) -> Float64Array:
        return np.clip(low + (u - 1.0) * span, low, upper[slots])

    with _one_blas_thread():
        for row in range(count):
            target, start = problems[row], start_rows[row]
            present = ~np.isnan(target).any(axis=-1)
            if not present.any():
                fitted[row], costs[row], iterations[row], success[row] = start, 0.0, 0, False
                messages.append(_NO_DATA)
                continue
            wi_p = np.ascontiguousarray(wi_rows[row][present], dtype=dtype)
            wo_p = np.ascontiguousarray(wo_rows[row][present], dtype=dtype)
            m = target[present]
            cos_theta = _cosine_factors(wi_rows[row][present], cosine, model)
            scale = np.maximum(m, max(_RELATIVE_FLOOR_FRACTION * float(m.max()), _RELATIVE_FLOOR))
            level = log_scale(m, cos_theta) if loss == "scaled_log" else 1.0
            root_weight = np.sqrt(weights[row][present])[:, None] if weights is not None else np.ones((len(m), 1))
            values = start.copy()
            last: dict[str, Float64Array] = {}

            def evaluate(x: Float64Array) -> tuple[Float64Array, Float64Array]:
                """Unweighted residuals (n, 3) and their Jacobian (n, 3, len(slots)) at x, kept for the next call."""
                if last.get("x") is None or not np.array_equal(last["x"], x):
                    values[slots] = x
                    material = _material_of(values)
                    if precision == "float32":
                        g = eval_grad(material, wi_p, wo_p, model=model, check=False)
                    else:
                        g = reference.eval_grad(material, wi_p, wo_p, model=model)
                    r, d = _residual_and_jacobian(g.value.astype(np.float64), g.jacobian.astype(np.float64), m,
                                                  cos_theta, loss, scale, level)
                    last.update(x=x.copy(), r=r, d=d[..., slots])
                return last["r"], last["d"]

            if not slots:
                x = start[slots]
                residual = evaluate(x)[0]
                fitted[row], iterations[row], success[row] = start, 0, True
                costs[row] = 0.5 * float(np.sum((residual * root_weight) ** 2))
                messages.append(_NOTHING_FITTED)
                residuals_out[row][present] = residual
                continue
            solution = least_squares(
                lambda u: (evaluate(x_of(u))[0] * root_weight).reshape(-1), 1.0 + (start[slots] - low) / span,
                jac=lambda u: (evaluate(x_of(u))[1] * span * root_weight[..., None]).reshape(-1, len(slots)),
                bounds=(1.0, 2.0), method="trf", x_scale="jac", max_nfev=max_iterations)
            values[slots] = x_of(solution.x)
            moved = _inert.reset(values, start, slots, *_evaluators(wi_rows[row][present], wo_rows[row][present], model, precision))
            reset_names[row] = moved or []
            fitted[row] = values
            costs[row] = solution.cost if moved is None else \
                0.5 * float(np.sum((evaluate(values[slots].copy())[0] * root_weight) ** 2))
            iterations[row] = solution.njev if solution.njev is not None else solution.nfev
            success[row] = solution.success
            messages.append(solution.message)
            residuals_out[row][present] = evaluate(values[slots].copy())[0]
    return fitted, costs, iterations, success, messages, residuals_out, reset_names


def _fit_batched(wi: NDArray[Any], wo: NDArray[Any], problems: NDArray[Any], weights: Float64Array | None,
                 start: Float64Array, lower: Float64Array, upper: Float64Array, slots: list[int], loss: str,
                 cosine: bool, model: Model, precision: str, max_iterations: int, threads: int) -> _FitArrays:
    """Every problem together by the batched solver (module _solver)."""
    count, n = problems.shape[:2]
    present: NDArray[np.bool_] = ~np.any(np.isnan(problems), axis=-1)  # (B, N)
    has_data = np.any(present, axis=1)
    m = np.where(present[..., None], problems, 0.0)
    cos_theta = np.broadcast_to(_cosine_factors(wi, cosine, model), (count, n))[..., None]
    root_weight = (np.sqrt(weights) if weights is not None else np.ones((count, n)))[..., None]
    floor = np.maximum(_RELATIVE_FLOOR_FRACTION * m.max(axis=(1, 2)), _RELATIVE_FLOOR)[:, None, None]
    # the log losses' s per problem (1/sr for "log")
    level = np.ones(count)
    if loss == "scaled_log":
        complete = np.all(present, axis=1)
        level[complete] = log_scales(m[complete], cos_theta[complete, :, 0])
        for row in np.flatnonzero(has_data & ~complete):
            here = present[row]
            level[row] = log_scale(m[row][here], cos_theta[row, :, 0][here])
    # r = (u(g f) - target) scale: the loss folded into the gain g, target and scale (docs/fitting.md)
    gain = np.ones(count)
    if loss == "relative":
        target, scale, kernel_cosine, loss_code = m, root_weight / np.maximum(m, floor), False, 0
    elif loss in ("log", "scaled_log"):
        target, scale, kernel_cosine, loss_code = np.log1p(m * cos_theta / level[:, None, None]), root_weight, cosine, 1
        gain = 1.0 / level
    else:
        target, scale, kernel_cosine, loss_code = m * cos_theta, root_weight, cosine, 0
    scale = np.where(present[..., None], np.broadcast_to(scale, problems.shape), 0.0)
    # each problem's scale divided by its largest (the same minimum; float32 sums stay in range)
    top = scale.max(axis=(1, 2))
    scale = scale / np.where(top > 0.0, top, 1.0)[:, None, None]
    full_start = np.broadcast_to(start, (count, start.shape[-1])).copy()
    solved = np.flatnonzero(has_data).astype(np.int64)
    slot_index = np.asarray(slots, dtype=np.int64)
    fitted = full_start.copy()
    iterations = np.zeros(count, np.int64)
    success = np.zeros(count, bool)
    messages = [_NO_DATA] * count
    reset_names: list[list[str]] = [[] for _ in range(count)]
    if slots and len(solved):
        if precision == "float32":
            equations = _solver.float32_equations(
                np.ascontiguousarray(wi, dtype=np.float32), np.ascontiguousarray(wo, dtype=np.float32),
                np.ascontiguousarray(target, dtype=np.float32), np.ascontiguousarray(scale, dtype=np.float32),
                np.ascontiguousarray(gain, dtype=np.float32), full_start, slots, solved, loss_code, kernel_cosine,
                _validate.model_index(model), threads)
        else:
            equations = _solver.float64_equations(_material_of, wi, wo, np.broadcast_to(target, problems.shape),
                                                  scale, gain, full_start, slots, solved, loss_code, kernel_cosine,
                                                  model)
        solution = _solver.levenberg_marquardt(equations, full_start[np.ix_(solved, slot_index)], lower[slots],
                                               upper[slots], max_iterations, _FTOL[precision])
        fitted[np.ix_(solved, slot_index)] = solution.x
        iterations[solved] = solution.iterations
        success[solved] = solution.success
        for j, row in enumerate(solved):
            messages[row] = solution.message[j]
        for row, names in zip(solved, _reset_inert(fitted, full_start, slots, solved, wi, wo, present, model,
                                                    precision, threads)):
            reset_names[row] = names
    elif len(solved):
        success[solved] = True
        for row in solved:
            messages[row] = _NOTHING_FITTED
    residuals_out, costs = _residuals_at(fitted, wi, wo, problems, present, m, cos_theta, root_weight, floor, level,
                                         loss, model, precision, threads)
    return fitted, costs, iterations, success, messages, residuals_out, reset_names


def _reset_inert(fitted: Float64Array, start: Float64Array, slots: list[int], solved: NDArray[np.int64],
                 wi: NDArray[Any], wo: NDArray[Any], present: NDArray[np.bool_], model: Model, precision: str,
                 threads: int) -> list[list[str]]:
    """_inert.reset for each solved problem, in place in ``fitted``: f and its Jacobian of a few
    problems at a time in one call, then the check of each problem that may have a
    parameter without effect (_inert.candidates), on its present samples."""
    n = present.shape[1]
    chunk = max(1, (1 << 22) // max(1, n * 3 * fitted.shape[1]))
    names: list[list[str]] = []
    for begin in range(0, len(solved), chunk):
        rows = solved[begin:begin + chunk]
        wi_part, wo_part = (wi[rows], wo[rows]) if wi.ndim == 3 else (wi, wo)
        material = _material_of(fitted[rows]).reshape(-1, 1)
        if precision == "float32":
            g = eval_grad(material, wi_part.astype(np.float32), wo_part.astype(np.float32), model=model, check=False,
                          threads=threads or None)
        else:
            g = reference.eval_grad(material, wi_part, wo_part, model=model)
        maybe = _inert.candidates(g.value, g.jacobian, present[rows], fitted[rows], start[rows], slots)
        names.extend([] for _ in range(int(np.count_nonzero(~maybe))))
        for j, row in zip(np.flatnonzero(maybe), rows[maybe]):
            here = present[row]
            value, jacobian = g.value[j][here].astype(np.float64), g.jacobian[j][here].astype(np.float64)
            _, evaluate_value = _evaluators(wi[row][here] if wi.ndim == 3 else wi[here],
                                            wo[row][here] if wo.ndim == 3 else wo[here], model, precision)
            moved = _inert.reset(fitted[row], start[row], slots, lambda values: (value, jacobian), evaluate_value)
            names.append(moved or [])
    return names


def _residuals_at(fitted: Float64Array, wi: NDArray[Any], wo: NDArray[Any], problems: NDArray[Any],
                  present: NDArray[np.bool_], m: Float64Array, cos_theta: Float64Array, root_weight: Float64Array,
                  floor: Float64Array, level: Float64Array, loss: str, model: Model, precision: str,
                  threads: int) -> tuple[Float64Array, Float64Array]:
    """The unweighted residuals (NaN where a sample is missing) and ½ Σ (weighted residual)² of every
    problem at its fitted material, a few problems at a time."""
    count, n = problems.shape[:2]
    residuals = np.full(problems.shape, np.nan)
    costs = np.zeros(count)
    chunk = max(1, (1 << 20) // max(1, n))
    for begin in range(0, count, chunk):
        rows = slice(begin, min(count, begin + chunk))
        material = _material_of(fitted[rows]).reshape(-1, 1)
        wi_part, wo_part = (wi[rows], wo[rows]) if wi.ndim == 3 else (wi, wo)
        if precision == "float32":
            value = eval(material, wi_part.astype(np.float32), wo_part.astype(np.float32), model=model, check=False,
                         threads=threads or None).astype(np.float64)
        else:
            value = reference.eval(material, wi_part, wo_part, model=model)
        c, mm = cos_theta[rows], m[rows]
        if loss in ("log", "scaled_log"):
            s = level[rows][:, None, None]
            r = np.log1p(value * c / s) - np.log1p(mm * c / s)
        elif loss == "relative":
            r = (value - mm) / np.maximum(mm, floor[rows])
        else:
            r = (value - mm) * c
        here = present[rows][..., None]
        residuals[rows] = np.where(here, r, np.nan)
        costs[rows] = 0.5 * np.sum(np.where(here, r * root_weight[rows], 0.0) ** 2, axis=(1, 2))
    return residuals, costs


def _evaluators(wi: Float64Array, wo: Float64Array, model: Model, precision: str) -> tuple[
        Callable[[Float64Array], tuple[Float64Array, Float64Array]], Callable[[Float64Array], Float64Array]]:
    """f and ∂f/∂slot (a column per slot, 13 or 16), and f alone, at slot values over the pairs, in the
    fit's precision."""
    if precision == "float32":
        def gradient(values: Float64Array) -> Any:
            return eval_grad(_material_of(values), wi, wo, model=model, check=False)
    else:
        def gradient(values: Float64Array) -> Any:
            return reference.eval_grad(_material_of(values), wi, wo, model=model)

    def both(values: Float64Array) -> tuple[Float64Array, Float64Array]:
        g = gradient(values)
        return g.value, g.jacobian
    return both, lambda values: gradient(values).value


def _determines_anisotropy(wi: NDArray[Any], wo: NDArray[Any]) -> bool:
    """Whether the pairs' half vectors span more than one plane through the normal: with
    every half vector at one azimuth φh (mod π), as a MERL table's pairs
    (``merl_pairs()``), an anisotropic GGX of roughness r and one of another aspect
    match at every pair for some r', so the data cannot tell them apart."""
    h = wi + wo
    h_xy = h[..., :2].reshape(-1, 2)
    length = np.hypot(h_xy[:, 0], h_xy[:, 1])
    off_normal = length > 1e-6 * np.linalg.norm(h.reshape(-1, 3), axis=1)
    if off_normal.sum() < 2:
        return False
    # the doubled azimuth (φh and φh + π are one plane) as a unit vector; one plane = one point
    phi = np.arctan2(h_xy[off_normal, 1], h_xy[off_normal, 0])
    doubled = np.stack([np.cos(2.0 * phi), np.sin(2.0 * phi)], axis=-1)
    return bool(np.max(np.linalg.norm(doubled - doubled[0], axis=1)) > 1e-3)
