"""The batched least-squares solver of :func:`principled_brdf.fit` (docs/fitting.md).

Levenberg-Marquardt over B problems at once, each with its own parameters,
damping and convergence. An iteration asks :class:`NormalEquations` for the
normal equations of every unfinished problem at its trial point (one pass of
the kernels over all their pairs, reduced per problem in C++: JᵀJ, Jᵀr and
Σ r², never the Jacobian), then takes each problem's step from them in
float64: the damped system (JᵀJ + λ D) δ = -Jᵀr (Marquardt's scaling D, the
largest diagonal of JᵀJ seen) over the parameters not held by a bound, then
projected onto the bounds. A step that lowers the cost is taken and λ shrinks
with the gain ratio (Nielsen's rule); one that does not is refused and λ
grows. Every operation is per problem, elementwise over the batch axis or
in a fixed order over the parameters, so a problem's result does not depend on
the other problems it is solved with.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _core, _float64

if TYPE_CHECKING:
    from collections.abc import Callable

    from numpy.typing import NDArray

    from ._typing import Float64Array, Model

__all__ = ["NormalEquations", "Solution", "levenberg_marquardt"]

# Termination: the relative decrease of the cost (ftol) and the size of a step
# against the parameters (xtol), as scipy's least_squares names them.
_XTOL = 1e-8
_INITIAL_DAMPING = 1e-3
# The largest move of a parameter in one step, as a fraction of its bounds'
# span, at the start: a trust radius over the damped step (Moré 1978) that
# grows where the model predicts the cost well and shrinks where it does not,
# so a first Gauss-Newton step from a poor start cannot leap into a flat
# region (a clamp, a bound) it will not leave.
_INITIAL_RADIUS = 0.25
_MAX_DAMPING = 1e16
# the smallest scale of a parameter against the largest diagonal of JᵀJ: a
# parameter the data do not determine (a zero column) still gets a damped,
# finite step
_SCALE_FLOOR = 1e-12

CONVERGED_COST = "the cost's relative decrease fell below ftol"
CONVERGED_STEP = "the step fell below xtol against the parameters"
CONVERGED_ZERO = "the cost is 0: the model matches every sample"
STOPPED_DAMPING = "no step lowers the cost any further (damping at its limit)"
STOPPED_ITERATIONS = "the most evaluations (max_iterations) were made"


@dataclass
class NormalEquations:
    """What :func:`levenberg_marquardt` evaluates: for the problems ``rows``
    and their fitted parameters ``x`` (len(rows), P), the upper triangle of
    JᵀJ by rows (len(rows), P (P + 1) / 2), Jᵀr (len(rows), P) and Σ r²."""

    evaluate: Callable[[NDArray[np.int64], Float64Array], tuple[Float64Array, Float64Array, Float64Array]]


@dataclass
class Solution:
    x: Float64Array  # (B, P)
    iterations: NDArray[np.int64]  # evaluations of the normal equations, per problem
    success: NDArray[np.bool_]
    message: list[str]


def _dot(a: Float64Array, b: Float64Array) -> Float64Array:
    """Σ_k a_k b_k per row, in the order of k."""
    total = a[:, 0] * b[:, 0]
    for k in range(1, a.shape[1]):
        total = total + a[:, k] * b[:, k]
    return total


def _quadratic(normal: Float64Array, s: Float64Array) -> Float64Array:
    """sᵀ A s per row, A given by its upper triangle by rows, in a fixed order."""
    width = s.shape[1]
    total = np.zeros(len(s))
    entry = 0
    for k in range(width):
        for l in range(k, width):
            term = normal[:, entry] * s[:, k] * s[:, l]
            total = total + (term if k == l else 2.0 * term)
            entry += 1
    return total


def _diagonal(normal: Float64Array, width: int) -> Float64Array:
    return normal[:, [k * width - k * (k - 1) // 2 for k in range(width)]]


def levenberg_marquardt(equations: NormalEquations, start: Float64Array, lower: Float64Array, upper: Float64Array,
                        max_iterations: int, ftol: float) -> Solution:
    """Minimise each problem's ½ Σ r² from ``start`` (B, P) within [lower, upper] (P,)."""
    count, width = start.shape
    x = np.clip(start, lower, upper)
    everyone = np.arange(count, dtype=np.int64)
    normal, gradient, cost = equations.evaluate(everyone, x)
    iterations = np.ones(count, np.int64)
    scale = np.maximum(_diagonal(normal, width), 0.0)
    damping = np.full(count, _INITIAL_DAMPING)
    growth = np.full(count, 2.0)
    radius = np.full(count, _INITIAL_RADIUS)
    span = np.where(upper > lower, upper - lower, 1.0)
    done = np.zeros(count, bool)
    success = np.zeros(count, bool)
    message = [""] * count

    def finish(rows: NDArray[np.int64], ok: bool, why: str) -> None:
        done[rows] = True
        success[rows] = ok
        for row in rows:
            message[row] = why

    finish(everyone[cost == 0.0], True, CONVERGED_ZERO)
    while True:
        active = np.flatnonzero(~done & (iterations >= max_iterations))
        finish(active, False, STOPPED_ITERATIONS)
        active = np.flatnonzero(~done)
        if len(active) == 0:
            break
        x_a, g_a, a_a = x[active], gradient[active], normal[active]
        # a parameter at a bound that the gradient pushes outwards is held there this step
        held = ((x_a <= lower) & (g_a > 0.0)) | ((x_a >= upper) & (g_a < 0.0))
        floor = _SCALE_FLOOR * np.max(scale[active], axis=1, initial=0.0)
        d = damping[active][:, None] * np.maximum(scale[active], np.maximum(floor, 1e-300)[:, None])
        step = _core.damped_steps(np.ascontiguousarray(a_a), np.ascontiguousarray(g_a), np.ascontiguousarray(d),
                                  np.ascontiguousarray(~held))
        solvable = np.isfinite(step).all(axis=1)
        step[~solvable] = 0.0
        s = np.clip(x_a + step, lower, upper) - x_a
        # within the trust radius: the projected step shortened along itself (it stays in the box)
        reach = np.max(np.abs(s) / span, axis=1, initial=0.0)
        limited = reach > radius[active]
        s[limited] *= (radius[active][limited] / reach[limited])[:, None]
        trial = np.clip(x_a + s, lower, upper)
        s = trial - x_a
        predicted = -(_dot(g_a, s) + 0.5 * _quadratic(a_a, s))  # the model's decrease of ½ Σ r²
        step_norm = np.sqrt(_dot(s, s))
        tiny_step = solvable & (step_norm <= _XTOL * (_XTOL + np.sqrt(_dot(x_a, x_a))))
        finish(active[tiny_step], True, CONVERGED_STEP)
        trying = solvable & ~tiny_step & (predicted > 0.0)
        # an unsolvable or useless step: more damping, no evaluation
        refuse_now = active[~solvable | (~tiny_step & (predicted <= 0.0))]
        damping[refuse_now] *= growth[refuse_now]
        growth[refuse_now] *= 2.0
        rows = active[trying]
        if len(rows):
            new_normal, new_gradient, new_cost = equations.evaluate(rows, trial[trying])
            iterations[rows] += 1
            old_cost = cost[rows]
            actual = 0.5 * (old_cost - new_cost)
            ratio = actual / predicted[trying]
            accept = np.isfinite(new_cost) & (actual > 0.0)
            was_limited = limited[trying]
            taken = rows[accept]
            x[taken] = trial[trying][accept]
            normal[taken], gradient[taken], cost[taken] = new_normal[accept], new_gradient[accept], new_cost[accept]
            scale[taken] = np.maximum(scale[taken], _diagonal(new_normal[accept], width))
            # a step the radius cut short: the radius answers for the model (doubled where it
            # predicted well, halved where poorly); any other: the damping (Nielsen's rule)
            radius[rows[was_limited & accept & (ratio > 0.75)]] *= 2.0
            radius[rows[was_limited & (~accept | (ratio < 0.25))]] *= 0.5
            damped = accept & ~was_limited
            shrink = 1.0 - (2.0 * ratio[damped] - 1.0) ** 3
            damping[rows[damped]] *= np.maximum(1.0 / 3.0, shrink)
            growth[taken] = 2.0
            refused = rows[~accept & ~was_limited]
            damping[refused] *= growth[refused]
            growth[refused] *= 2.0
            finish(taken[new_cost[accept] == 0.0], True, CONVERGED_ZERO)
            small = (actual[accept] <= ftol * 0.5 * old_cost[accept]) & (new_cost[accept] > 0.0) & ~was_limited[accept]
            finish(taken[small], True, CONVERGED_COST)
        stuck = active[(damping[active] > _MAX_DAMPING) & ~done[active]]
        finish(stuck, True, STOPPED_DAMPING)
    return Solution(x=x, iterations=iterations, success=success, message=message)


def float32_equations(wi: NDArray[Any], wo: NDArray[Any], target: NDArray[np.float32], scale: NDArray[np.float32],
                      gain: NDArray[np.float32], full_start: Float64Array, fitted: list[int],
                      problems: NDArray[np.int64], loss: int, cosine: bool, model: int, threads: int = 0,
                      isa: str = "") -> NormalEquations:
    """The normal equations by the SIMD kernels of r = (u(g f) - t) s: wi, wo
    (N, 3) or (B, N, 3) float32, target t and scale s (B, N, 3), gain g (B,),
    the start's slots (B, P) holding the parameters not fitted, ``fitted`` the
    slots fitted (increasing); the solver's problem j is row ``problems[j]`` of
    these arrays."""
    slots = np.ascontiguousarray(full_start, dtype=np.float32)
    fitted_index = np.asarray(fitted, dtype=np.int64)

    def evaluate(rows: NDArray[np.int64], x: Float64Array) -> tuple[Float64Array, Float64Array, Float64Array]:
        rows = problems[rows]
        slots[np.ix_(rows, fitted_index)] = x
        return _core.normal_equations(wi=wi, wo=wo, slots=slots, target=target, scale=scale, gain=gain, problems=rows,
                                      columns=fitted, loss=loss, cosine=cosine, model=model, threads=threads, isa=isa)

    return NormalEquations(evaluate)


def float64_equations(material_of: Callable[[Float64Array], Any], wi: NDArray[Any], wo: NDArray[Any],
                      target: Float64Array, scale: Float64Array, gain: Float64Array, full_start: Float64Array,
                      fitted: list[int],
                      problems: NDArray[np.int64], loss: int, cosine: bool, model: Model,
                      chunk_bytes: int = 1 << 26) -> NormalEquations:
    """The normal equations from the float64 reference's Jacobian, reduced by
    numpy a few problems at a time (each problem's sums over its own pairs)."""
    slots = np.array(full_start, dtype=np.float64)
    fitted_index = np.asarray(fitted, dtype=np.int64)
    pairs = target.shape[1]
    width = len(fitted)
    upper = [(k, l) for k in range(width) for l in range(k, width)]
    per_problem = wi.ndim == 3
    chunk = max(1, chunk_bytes // max(1, pairs * 3 * width * 8))

    def evaluate(rows: NDArray[np.int64], x: Float64Array) -> tuple[Float64Array, Float64Array, Float64Array]:
        rows = problems[rows]
        slots[np.ix_(rows, fitted_index)] = x
        normal = np.empty((len(rows), len(upper)))
        gradient = np.empty((len(rows), width))
        cost = np.empty(len(rows))
        for begin in range(0, len(rows), chunk):
            part = rows[begin:begin + chunk]
            material = material_of(slots[part]).reshape(len(part), 1)
            g = _float64.parameter_grad(material, wi[part] if per_problem else wi, wo[part] if per_problem else wo,
                                        model=model, cosine=cosine)
            f, jacobian = g.value * gain[part][:, None, None], g.jacobian[..., fitted] * gain[part][:, None, None, None]
            t, s = target[part], scale[part]
            if loss == 1:
                r, slope = (np.log1p(f) - t) * s, s / (1.0 + f)
            else:
                r, slope = (f - t) * s, s
            d = slope[..., None] * jacobian  # ∂r/∂p (b, n, 3, P)
            full = np.einsum("bnck,bncl->bkl", d, d)
            normal[begin:begin + len(part)] = np.stack([full[:, k, l] for k, l in upper], axis=1)
            gradient[begin:begin + len(part)] = np.einsum("bnck,bnc->bk", d, r)
            cost[begin:begin + len(part)] = np.einsum("bnc,bnc->b", r, r)
        return normal, gradient, cost

    return NormalEquations(evaluate)
