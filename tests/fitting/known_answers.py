"""What a fit must get right, measured on materials whose answer is known (docs/fitting.md#losses).

Two figures compare a fitted material with the BRDF that made the measurement:

- the directional albedo at normal incidence, E = ∫ f cos θl dωi with wo = n,
  per channel: by Gauss-Legendre quadrature in x = cos² θl (cos θl dωi =
  dx dφ / 2, and at wo = n an isotropic f does not depend on φ), on panels
  that crowd towards the specular peak at x = 1;
- the position of the peak of f cos θl as the light moves through the plane
  of incidence, for views at θo = 0°, 30°, 45° and 60°, as the MERL table's
  θd cell of the peak pair (i_θd = floor(θd / 1°), θd = (θl + θo) / 2 in that
  plane): within one cell is within about 2° of θl. (Its θh cell is no
  measure of the peak: those cells are 0.01° to 0.1° wide next to the mirror
  direction, where an off-specular peak moves by a few hundredths of a
  degree between distributions of one width.)

The measurements: microfacet BRDFs of other models (``pb.synthetic``), Lambert +
Blinn-Phong plastics (``blinn_phong_plastic``) and the library's own model with 5 %
multiplicative noise. ``python
tests/fitting/known_answers.py`` prints the table of docs/fitting.md (every
case × loss).
"""

from __future__ import annotations

import numpy as np

import principled_brdf as pb

# (θh, θd, φd) strides: every θh cell (the specular peak's), 1 in 36 of the others
MERL_STEP = (1, 3, 12)
VIEWS = np.radians([0.0, 30.0, 45.0, 60.0])
NOISE = 0.05
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
OWN = pb.Material(base_color=(0.2, 0.5, 0.7), roughness=0.35, specular=0.6, sheen=0.3, clearcoat=0.5)


def blinn_phong_plastic(diffuse, exponent, specular=0.04):
    """A Lambertian body under a normalised Blinn-Phong lobe, f = ρd/π + ks (n + 8)/(8π) (n·h)^n:
    a plastic of the games' shading models, with neither Fresnel factor nor shadowing (NaN below
    the horizon like the others)."""
    diffuse = np.asarray(diffuse, dtype=np.float64)

    def f(wi, wo):
        h = wi + wo
        cos_h = np.maximum(h[..., 2], 0.0) / np.linalg.norm(h, axis=-1)
        lobe = specular * (exponent + 8.0) / (8.0 * np.pi) * cos_h**exponent
        value = diffuse / np.pi + lobe[..., None]
        return np.where(((wi[..., 2] > 0) & (wo[..., 2] > 0))[..., None], value, np.nan)
    return f


def own_model(wi, wo):
    """The library's own model (float64 reference), NaN below the horizon like the others."""
    f = pb.reference.eval(OWN, wi, wo)
    return np.where(((wi[..., 2] > 0) & (wo[..., 2] > 0))[..., None], f, np.nan)


# name -> (f(wi, wo), multiplicative noise of the measurement)
CASES = {
    "gold, Beckmann α 0.2": (pb.synthetic.conductor("gold", 0.2), 0.0),
    "copper, GGX α 0.15": (pb.synthetic.conductor("copper", 0.15, distribution="ggx"), 0.0),
    "red plastic, GGX α 0.1": (pb.synthetic.plastic((0.5, 0.1, 0.05), 0.1), 0.0),
    "blue plastic, GGX α 0.3": (pb.synthetic.plastic((0.05, 0.15, 0.5), 0.3), 0.0),
    "dusty dielectric, Beckmann α 0.15": (pb.synthetic.dusty_dielectric(0.15), 0.0),
    "disney2014 + 5 % noise": (own_model, NOISE),
}
# beyond what the principled model represents (docs/fitting.md): shown in the table, not held by the tests
LIMITS = {
    # its 3.6 % came from a clearcoat imitating Beckmann's tail; without it (docs/fitting.md#lobes-the-data-do-not-need)
    # the GGX that fits the lobe's shape best is 12.5 % dark
    "aluminium, Beckmann α 0.3": (pb.synthetic.conductor("aluminium", 0.3), 0.0),
    "aluminium, Beckmann α 0.06": (pb.synthetic.conductor("aluminium", 0.06), 0.0),
    "dusty dielectric, Beckmann α 0.05": (pb.synthetic.dusty_dielectric(0.05), 0.0),
    "gold, Beckmann α 0.6": (pb.synthetic.conductor("gold", 0.6), 0.0),
    "copper, Beckmann α 0.5": (pb.synthetic.conductor("copper", 0.5), 0.0),
    "red plastic, Lambert + Blinn-Phong n 50": (blinn_phong_plastic((0.5, 0.1, 0.05), 50.0), 0.0),
    "grey plastic, Lambert + Blinn-Phong n 10": (blinn_phong_plastic((0.3, 0.3, 0.3), 10.0, 0.1), 0.0),
}


def measure(f, noise, values=None, seed=7):
    """The measured values at ``merl_pairs(step=MERL_STEP)``: ``values`` (read from a table) or f there,
    times exp(noise · N(0, 1))."""
    wi, wo = pb.measured.merl_pairs(step=MERL_STEP)
    m = f(wi, wo) if values is None else values
    if noise:
        m = m * np.exp(noise * np.random.default_rng(seed).standard_normal(m.shape))
    return wi, wo, m


def _panels():
    x, w = np.polynomial.legendre.leggauss(48)
    edges = [0.0, 0.5, 0.8, 0.9, 0.95, 0.98, 0.99, 0.995, 0.999, 0.9999, 1.0]
    nodes = np.concatenate([a + (b - a) * (x + 1) / 2 for a, b in zip(edges[:-1], edges[1:])])
    weights = np.concatenate([(b - a) / 2 * w for a, b in zip(edges[:-1], edges[1:])])
    return nodes, weights


def normal_albedo(f):
    """E (3,) at wo = n: π ∫ f(x) dx over x = cos² θl in [0, 1]."""
    x, weights = _panels()
    wi = np.stack([np.sqrt(1.0 - x), np.zeros_like(x), np.sqrt(x)], axis=-1)
    return np.pi * weights @ f(wi, np.array([0.0, 0.0, 1.0]))


def peak_cells(f, views=VIEWS):
    """The MERL θd cell of the peak of f cos θl (luminance) over θl in the plane of incidence, per view."""
    theta_l = np.radians(np.arange(0.0, 89.9, 0.01))
    wi = np.stack([-np.sin(theta_l), np.zeros_like(theta_l), np.cos(theta_l)], axis=-1)  # opposite wo's side
    cells = []
    for theta_o in views:
        wo = np.array([np.sin(theta_o), 0.0, np.cos(theta_o)])
        lobe = np.nan_to_num(f(wi, wo)) @ LUMINANCE * np.cos(theta_l)
        theta_d = 0.5 * (theta_l[np.argmax(lobe)] + theta_o)
        cells.append(min(int(theta_d / (np.pi / 2) * 90), 89))
    return np.array(cells)


def fitted_f(result, model="disney2014"):
    return lambda wi, wo: pb.reference.eval(result.material, wi, wo, model=model)


def errors(truth, result):
    """(the largest relative albedo error over the channels, the largest peak-cell distance over the views)."""
    albedo, fitted = normal_albedo(truth), normal_albedo(fitted_f(result))
    return float(np.max(np.abs(fitted / albedo - 1.0))), int(np.max(np.abs(peak_cells(fitted_f(result))
                                                                           - peak_cells(truth))))


def table(losses=("scaled_log", "log", "relative", "linear")):
    """The markdown table of docs/fitting.md: albedo error and peak-cell distance of the default fit per loss."""
    lines = ["| measured | " + " | ".join(f'`"{loss}"`' for loss in losses) + " |",
             "|---|" + "---|" * len(losses)]
    for name, (f, noise) in {**CASES, **LIMITS}.items():
        wi, wo, m = measure(f, noise)
        cells = []
        for loss in losses:
            albedo_error, peak_error = errors(f, pb.fit(wi, wo, m, loss=loss))
            cells.append(f"{albedo_error:.1%}, {peak_error}")
        lines.append(f"| {name}{' (limit)' if name in LIMITS else ''} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table())
