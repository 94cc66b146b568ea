"""Chi-square goodness of fit of a direction sampler against its pdf (docs/validation.md).

The upper hemisphere is cut into an equal-area grid of ``n_phi x n_cos`` cells
in ``(φ, cos θ)`` (``dω = dφ d cos θ``, so every cell has solid angle
``2π / (n_phi n_cos)``); everything at or below the horizon is one more cell.
The expected count of a cell is ``N ∫_cell pdf dω``, integrated by adaptive
Gauss-Legendre cubature (below), and the below-horizon cell expects the rest,
``N (1 - ∫_hemisphere pdf dω)``. Cells expecting fewer than 5 samples are
pooled into one; Pearson's statistic is referred to ``scipy.stats.chi2`` with
(cells - 1) degrees of freedom.

Whole sphere. With ``sphere=True`` (for samplers whose directions may lie
anywhere, e.g. with transmission) the ``n_cos`` rows cover cos θ in [-1, 1]
instead, so every cell has solid angle ``4π / (n_phi n_cos)`` (with ``n_cos``
even a row boundary lies on the horizon). There is no horizon to fall below:
the extra cell holds the invalid samples, those the caller flags in the mask
``invalid`` (e.g. returned with pdf 0) and those whose direction is zero or not
finite, and it expects ``N (1 - ∫_sphere pdf dω)``.

Cubature. Each cell starts as one region of the ``(φ, cos θ)`` plane (or two, below). A region's
integral is estimated with an ``order x order`` Gauss-Legendre rule and with the
same rule on its two halves along each axis; where the halves disagree with the
whole by more than the tolerance, the region is split along the axis that
disagrees most, and so on. Peaks much narrower than a region can fall between
the nodes of both estimates and go unseen, so the caller names them: every
region within a few ``peak_width`` of a peak direction is split until its
angular radius is below ``peak_width / 4``, whatever the estimates say.
Likewise a jump of the density along a circle of latitude can hide in a thin
band at a region's edge that no node reaches; the caller names such circles
by their cos θ (``cos_breaks``) and the cells they cross are cut there. On the
upper hemisphere the one jump of a reflection lobe is the horizon, a cell
boundary; on the whole sphere, microfacet lobes jump where the microfacet
horizon (``h_z = 0``) sends them: cos θ = ``-cos θo`` for reflection and
``-cos θo / η`` for refraction into a medium of relative index ``η``.

Usage::

    result = chi_square_test(wi, lambda w: pdf_of(w), peaks=[mirror], peak_width=alpha)
    assert result.p_value > sidak_threshold(cases), result.describe()

    # a BSDF sampler, over the whole sphere
    result = chi_square_test(wi, pdf_of, sphere=True, invalid=pdf == 0, peaks=[mirror, refracted],
                             peak_width=alpha, cos_breaks=[-wo[2], -wo[2] / eta])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

SIGNIFICANCE = 0.01
MIN_EXPECTED = 5.0
GRID = (50, 50)  # (n_phi, n_cos): at least 50 x 50 (docs/validation.md)


def sidak_threshold(cases: int, significance: float = SIGNIFICANCE) -> float:
    """Per-case significance that keeps the family-wise rate at ``significance`` over ``cases`` tests."""
    return 1.0 - (1.0 - significance) ** (1.0 / cases)


# --------------------------------------------------------------------------
# the grid


def spherical_to_direction(phi: np.ndarray, cos_theta: np.ndarray) -> np.ndarray:
    sin_theta = np.sqrt(np.maximum(0.0, (1.0 - cos_theta) * (1.0 + cos_theta)))
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)


def cell_counts(directions: np.ndarray, n_phi: int, n_cos: int, below=None, *, sphere: bool = False,
                invalid=None):
    """``(counts (n_cos, n_phi), below_count)``: how many directions fall in each cell.

    A direction with ``z <= 0`` (or flagged in the boolean mask ``below`` or
    ``invalid``) counts as below the horizon. With ``sphere`` the rows cover
    cos θ in [-1, 1] and the second number counts the invalid samples: those
    flagged in ``invalid`` and those whose direction is zero or not finite
    (``below`` is then an error: there is no horizon).
    """
    w = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    if sphere:
        if below is not None:
            raise ValueError("below: no horizon on the whole sphere; flag samples with invalid=")
        is_below = ~np.all(np.isfinite(w), axis=1) | ~np.any(w != 0.0, axis=1)
    else:
        is_below = w[:, 2] <= 0.0
        if below is not None:
            is_below |= np.asarray(below, dtype=bool).reshape(-1)
    if invalid is not None:
        is_below |= np.asarray(invalid, dtype=bool).reshape(-1)
    above = w[~is_below]
    phi = np.mod(np.arctan2(above[:, 1], above[:, 0]), 2.0 * np.pi)
    i_phi = np.minimum((phi * (n_phi / (2.0 * np.pi))).astype(np.int64), n_phi - 1)
    if sphere:
        i_cos = np.clip(np.floor((above[:, 2] + 1.0) * (0.5 * n_cos)).astype(np.int64), 0, n_cos - 1)
    else:
        i_cos = np.minimum((above[:, 2] * n_cos).astype(np.int64), n_cos - 1)
    counts = np.bincount(i_cos * n_phi + i_phi, minlength=n_phi * n_cos).reshape(n_cos, n_phi)
    return counts, int(is_below.sum())


# --------------------------------------------------------------------------
# adaptive cubature over the cells


def _gauss_legendre(order: int):
    nodes, weights = np.polynomial.legendre.leggauss(order)
    return 0.5 * (nodes + 1.0), 0.5 * weights  # on [0, 1]


class _Rule:
    """The tensor Gauss-Legendre rule applied to many rectangles of the (φ, cos θ) plane at once."""

    def __init__(self, pdf_fn, order: int):
        self.pdf_fn = pdf_fn
        nodes, weights = _gauss_legendre(order)
        self.node_phi, self.node_cos = (a.ravel() for a in np.meshgrid(nodes, nodes, indexing="ij"))
        self.node_weight = np.outer(weights, weights).ravel()
        self.evaluations = 0

    def __call__(self, phi0, phi1, cos0, cos1) -> np.ndarray:
        d_phi = (phi1 - phi0)[:, None]
        d_cos = (cos1 - cos0)[:, None]
        phi = phi0[:, None] + d_phi * self.node_phi
        cos_theta = cos0[:, None] + d_cos * self.node_cos
        values = np.asarray(self.pdf_fn(spherical_to_direction(phi, cos_theta).reshape(-1, 3)), dtype=np.float64)
        self.evaluations += values.size
        values = values.reshape(phi.shape + values.shape[1:])
        area = (d_phi * d_cos)[:, 0]
        weight = self.node_weight.reshape((1, -1) + (1,) * (values.ndim - 2))
        return (values * weight).sum(axis=1) * area.reshape((-1,) + (1,) * (values.ndim - 2))


def _angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle between unit vectors, accurate for small angles (atan2 of |a x b| and a·b)."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def _near_peak(phi0, phi1, cos0, cos1, peaks: np.ndarray, peak_width: float) -> np.ndarray:
    """Regions whose angular radius exceeds ``peak_width / 4`` and that lie within
    ``3 peak_width`` of a peak direction."""
    phi_mid, cos_mid = 0.5 * (phi0 + phi1), 0.5 * (cos0 + cos1)
    center = spherical_to_direction(phi_mid, cos_mid)
    radius = np.zeros(phi0.shape)
    for phi in (phi0, phi_mid, phi1):
        for cos_theta in (cos0, cos_mid, cos1):
            radius = np.maximum(radius, _angle_between(center, spherical_to_direction(phi, cos_theta)))
    near = np.zeros(phi0.shape, dtype=bool)
    for peak in peaks:
        near |= _angle_between(center, np.broadcast_to(peak, center.shape)) <= radius + 3.0 * peak_width
    return near & (radius > 0.25 * peak_width)


def integrate_cells(
    pdf_fn,
    n_phi: int = GRID[0],
    n_cos: int = GRID[1],
    *,
    sphere: bool = False,
    peaks=(),
    peak_width: float | None = None,
    cos_breaks=(),
    order: int = 4,
    atol: float = 1e-10,
    rtol: float = 1e-6,
    max_rounds: int = 60,
    return_evaluations: bool = False,
):
    """``∫ pdf dω`` over each cell of the grid, ``(n_cos, n_phi)`` (row = cos θ bin).

    ``pdf_fn`` maps unit directions ``(M, 3)`` (all with ``z`` in (0, 1), or in
    (-1, 1) with ``sphere``: the rows then cover the whole sphere) to
    densities ``(M,)`` or values ``(M, k)`` (then the result is ``(n_cos, n_phi, k)``
    and the tolerance applies to the largest component). A region is accepted
    when its two-halves estimates agree with the whole within
    ``max(atol, rtol |I|)``; ``peaks`` (unit vectors, in either hemisphere with
    ``sphere``) with ``peak_width`` (radians) force refinement around narrow
    peaks, and ``cos_breaks`` (values of cos θ where the density may jump) cut
    the cells they cross before the cubature starts (module docstring).
    """
    rule = _Rule(pdf_fn, order)
    peaks = np.asarray(peaks, dtype=np.float64).reshape(-1, 3)
    if len(peaks) and not peak_width:
        raise ValueError("peak_width: required with peaks")
    phi_edges = np.linspace(0.0, 2.0 * np.pi, n_phi + 1)
    cos_edges = np.linspace(-1.0 if sphere else 0.0, 1.0, n_cos + 1)
    # The rows cut at the breaks: band k spans bounds[k]..bounds[k + 1] of row row_of[k].
    breaks = np.asarray(cos_breaks, dtype=np.float64).ravel()
    bounds = np.union1d(cos_edges, breaks[(breaks > cos_edges[0]) & (breaks < cos_edges[-1])])
    row_of = np.searchsorted(cos_edges, bounds[:-1], side="right") - 1
    band, i_phi = (a.ravel() for a in np.meshgrid(np.arange(len(row_of)), np.arange(n_phi), indexing="ij"))
    phi0, phi1 = phi_edges[i_phi], phi_edges[i_phi + 1]
    cos0, cos1 = bounds[band], bounds[band + 1]
    cell = row_of[band] * n_phi + i_phi
    whole = rule(phi0, phi1, cos0, cos1)
    total = np.zeros((n_cos * n_phi,) + whole.shape[1:])

    for _ in range(max_rounds):
        if cell.size == 0:
            break
        phi_mid, cos_mid = 0.5 * (phi0 + phi1), 0.5 * (cos0 + cos1)
        halves_phi = (rule(phi0, phi_mid, cos0, cos1), rule(phi_mid, phi1, cos0, cos1))
        halves_cos = (rule(phi0, phi1, cos0, cos_mid), rule(phi0, phi1, cos_mid, cos1))
        by_phi = halves_phi[0] + halves_phi[1]
        by_cos = halves_cos[0] + halves_cos[1]
        error_phi = np.abs(by_phi - whole)
        error_cos = np.abs(by_cos - whole)
        if error_phi.ndim > 1:  # vector-valued: the worst component decides
            error_phi, error_cos = error_phi.max(axis=1), error_cos.max(axis=1)
            size = np.abs(by_cos).max(axis=1)
        else:
            size = np.abs(by_cos)
        tolerance = np.maximum(atol, rtol * size)
        split = np.maximum(error_phi, error_cos) > tolerance
        if len(peaks):
            forced = _near_peak(phi0, phi1, cos0, cos1, peaks, peak_width)
            split |= forced
        else:
            forced = np.zeros_like(split)
        done = ~split
        np.add.at(total, cell[done], 0.5 * (by_phi[done] + by_cos[done]))

        # Split along the axis whose halves disagree most; a forced split takes the
        # axis of larger angular extent (the φ extent on the region's widest circle of
        # latitude, at its cos θ nearest 0: cos0 on the upper hemisphere).
        along_phi = error_phi > error_cos
        cos_widest = np.where((cos0 < 0.0) & (cos1 > 0.0), 0.0, np.minimum(np.abs(cos0), np.abs(cos1)))
        extent_phi = (phi1 - phi0) * np.sqrt(np.maximum(0.0, 1.0 - cos_widest * cos_widest))
        extent_cos = np.arccos(np.clip(cos0, -1.0, 1.0)) - np.arccos(np.clip(cos1, -1.0, 1.0))
        along_phi = np.where(forced, extent_phi > extent_cos, along_phi)[split]
        s = split
        p0, p1, pm, c0, c1, cm, cl = phi0[s], phi1[s], phi_mid[s], cos0[s], cos1[s], cos_mid[s], cell[s]
        first = np.where(_expand(along_phi, whole), halves_phi[0][s], halves_cos[0][s])
        second = np.where(_expand(along_phi, whole), halves_phi[1][s], halves_cos[1][s])
        phi0 = np.concatenate([p0, np.where(along_phi, pm, p0)])
        phi1 = np.concatenate([np.where(along_phi, pm, p1), p1])
        cos0 = np.concatenate([c0, np.where(along_phi, c0, cm)])
        cos1 = np.concatenate([np.where(along_phi, c1, cm), c1])
        cell = np.concatenate([cl, cl])
        whole = np.concatenate([first, second])
    else:
        raise RuntimeError(f"integrate_cells: {cell.size} regions still unresolved after {max_rounds} rounds")
    total = total.reshape((n_cos, n_phi) + whole.shape[1:])
    return (total, rule.evaluations) if return_evaluations else total


def _expand(mask: np.ndarray, like: np.ndarray) -> np.ndarray:
    return mask.reshape(mask.shape + (1,) * (like.ndim - 1))


# --------------------------------------------------------------------------
# the test


@dataclass
class ChiSquareResult:
    p_value: float
    statistic: float
    dof: int
    samples: int
    integral: float  # ∫ pdf over the upper hemisphere, or the sphere (cubature)
    observed: np.ndarray  # (n_cos, n_phi)
    expected: np.ndarray  # (n_cos, n_phi)
    observed_below: int  # with sphere: the invalid samples
    expected_below: float
    pooled_cells: int
    sphere: bool = False

    def describe(self, worst: int = 5) -> str:
        """A summary with the cells that contribute most, for assertion messages."""
        contribution = (self.observed - self.expected) ** 2 / np.maximum(self.expected, 1e-300)
        order = np.argsort(contribution.ravel())[::-1][:worst]
        n_cos, n_phi = self.expected.shape
        cos_low, cos_step = (-1.0, 2.0 / n_cos) if self.sphere else (0.0, 1.0 / n_cos)
        cells = ", ".join(
            f"(cos {cos_low + (k // n_phi) * cos_step:.2f}.., phi {2 * np.pi * (k % n_phi) / n_phi:.2f}..): "
            f"{self.observed.ravel()[k]} vs {self.expected.ravel()[k]:.1f}"
            for k in order
        )
        catch_all = "invalid" if self.sphere else "below horizon"
        return (
            f"p = {self.p_value:.3g}, chi2 = {self.statistic:.1f} on {self.dof} dof, N = {self.samples}, "
            f"∫pdf = {self.integral:.6f}, {catch_all} {self.observed_below} vs {self.expected_below:.1f}, "
            f"{self.pooled_cells} cells pooled; worst cells: {cells}"
        )


def pearson_pooled(observed: np.ndarray, expected: np.ndarray, min_expected: float = MIN_EXPECTED):
    """``(statistic, dof, pooled_cells)`` with every cell expecting fewer than ``min_expected``
    pooled into one; if that pool still expects too few, it joins the smallest remaining cell."""
    observed = np.asarray(observed, dtype=np.float64).ravel()
    expected = np.asarray(expected, dtype=np.float64).ravel()
    small = expected < min_expected
    obs, exp = observed[~small], expected[~small]
    pooled_obs, pooled_exp = observed[small].sum(), expected[small].sum()
    if small.any():
        if pooled_exp >= min_expected or obs.size == 0:
            obs, exp = np.append(obs, pooled_obs), np.append(exp, pooled_exp)
        else:
            k = int(np.argmin(exp))
            obs[k] += pooled_obs
            exp[k] += pooled_exp
    exp = np.maximum(exp, 1e-300)
    statistic = float(np.sum((obs - exp) ** 2 / exp))
    return statistic, max(obs.size - 1, 1), int(small.sum())


def chi_square_test(
    directions,
    pdf_fn,
    *,
    n_phi: int = GRID[0],
    n_cos: int = GRID[1],
    below=None,
    peaks=(),
    peak_width: float | None = None,
    sphere: bool = False,
    invalid=None,
    **cubature,
) -> ChiSquareResult:
    """Pearson's test of sampled ``directions`` ``(N, 3)`` against ``pdf_fn`` (module docstring).

    ``below`` (or ``invalid``) optionally flags samples to count as below the
    horizon whatever their ``z`` (e.g. those the sampler returned with pdf 0); ``peaks`` and
    ``peak_width`` and further keywords go to :func:`integrate_cells`. With
    ``sphere`` the grid covers the whole sphere and the extra cell holds the
    invalid samples: those flagged in ``invalid`` (``below`` is then an error)
    and those with a zero or non-finite direction (:func:`cell_counts`).
    """
    directions = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    n = len(directions)
    observed, observed_below = cell_counts(directions, n_phi, n_cos, below, sphere=sphere, invalid=invalid)
    probability = integrate_cells(pdf_fn, n_phi, n_cos, sphere=sphere, peaks=peaks, peak_width=peak_width,
                                  **cubature)
    integral = float(probability.sum())
    expected = n * probability
    expected_below = max(0.0, n * (1.0 - integral))
    statistic, dof, pooled = pearson_pooled(np.append(observed.ravel(), observed_below),
                                            np.append(expected.ravel(), expected_below))
    return ChiSquareResult(
        p_value=float(stats.chi2.sf(statistic, dof)),
        statistic=statistic,
        dof=dof,
        samples=n,
        integral=integral,
        observed=observed,
        expected=expected,
        observed_below=observed_below,
        expected_below=expected_below,
        pooled_cells=pooled,
        sphere=sphere,
    )


def chi_square_pvalue(directions, pdf_fn, **options) -> float:
    """The p-value of :func:`chi_square_test`."""
    return chi_square_test(directions, pdf_fn, **options).p_value
