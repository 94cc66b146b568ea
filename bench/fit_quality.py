"""How well pb.fit recovers materials of other models (docs/fitting.md#the-benchmark).

Each material is written from a model that is not the principled one
(``pb.synthetic``: conductors by their complex index under Beckmann, Blinn-Phong
and height-correlated GGX; plastics of a Lambert or Oren-Nayar body under a
rough dielectric coat; Ward and Ashikhmin-Shirley brushed metals; a satin),
sampled at a MERL table's cells (1,458,000 pairs; an anisotropic material
averaged over the half vector's azimuth, as a table of a sample turned about its
normal holds it) and fitted, from the table's coarse cells
(``MERL_STEP``), by every loss and method, with and without the cells' solid
angles as weights. Missing-cell variants lose the cells of θd < 2° (where a
gonioreflectometer's source hides its detector) and a quarter of the rest at
random. Per fit, against the complete table:

- the directional albedo at normal incidence and the hemispherical albedo (its
  cosine-weighted mean over views), the largest relative error over the
  channels, both by the same quadrature of the data and of the fit
  (:func:`albedos`);
- the image error, ``‖fit - data‖ / ‖data‖`` over a sphere's pixels under the
  studio and the outdoor maps, both rendered through the data's estimator on
  the same points (:func:`principled_brdf.fit_pictures.compare`'s);
- the lobes the fit turned on (``metallic`` above 0.05, ``clearcoat``,
  ``sheen`` above 0.01, ``subsurface`` above 0.05), and whether one the
  material's kind has no use for (clearcoat or sheen on a bare conductor,
  metallic on a dielectric).

``python bench/fit_quality.py`` runs it and prints the tables of
docs/fitting.md; ``--json PATH`` keeps every figure.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time

import numpy as np

import principled_brdf as pb
from principled_brdf.render import render_sphere

S = pb.synthetic
MERL_STEP = (1, 3, 12)  # every θh cell (the specular peak's), 1 in 36 of the others
ENVIRONMENTS = ("studio", "outdoor")
RESOLUTION, SAMPLES = 48, 96  # the pictures of the image error (about 1,800 pixels)

# name -> (kind, f(wi, wo)); kind says which lobes the material has no use for
MATERIALS = {
    "gold, Beckmann α 0.2": ("conductor", S.conductor("gold", 0.2)),
    "copper, Beckmann α 0.35": ("conductor", S.conductor("copper", 0.35)),
    "aluminium, Beckmann α 0.1": ("conductor", S.conductor("aluminium", 0.1)),
    "silver, Beckmann α 0.15": ("conductor", S.conductor("silver", 0.15)),
    "chrome, Beckmann α 0.25": ("conductor", S.conductor("chrome", 0.25)),
    "gold, Blinn-Phong n 48": ("conductor", S.conductor("gold", 0.2, distribution="blinn_phong")),
    "silver, Blinn-Phong n 200": ("conductor", S.conductor("silver", 0.1, distribution="blinn_phong")),
    "chrome, Blinn-Phong n 20": ("conductor", S.conductor("chrome", 0.3, distribution="blinn_phong")),
    "copper, GGX α 0.15": ("conductor", S.conductor("copper", 0.15, distribution="ggx")),
    "aluminium, GGX α 0.4": ("conductor", S.conductor("aluminium", 0.4, distribution="ggx")),
    "silver, GGX α 0.06": ("conductor", S.conductor("silver", 0.06, distribution="ggx")),
    "chrome, GGX α 0.2": ("conductor", S.conductor("chrome", 0.2, distribution="ggx")),
    "red plastic, Lambert under GGX α 0.1": ("dielectric", S.layered_plastic((0.5, 0.1, 0.05), 0.1)),
    "blue plastic, Lambert under Beckmann α 0.3": ("dielectric", S.layered_plastic((0.05, 0.15, 0.5), 0.3,
                                                                                   distribution="beckmann")),
    "green plastic, Oren-Nayar σ 0.5 under GGX α 0.2": ("dielectric", S.layered_plastic((0.1, 0.4, 0.1), 0.2,
                                                                                        sigma=0.5)),
    "white plastic, Oren-Nayar σ 0.3 under Beckmann α 0.08": ("dielectric", S.layered_plastic(
        (0.8, 0.8, 0.75), 0.08, distribution="beckmann", sigma=0.3)),
    "grey plastic, Lambert under Blinn-Phong n 20, η 1.6": ("dielectric", S.layered_plastic(
        (0.3, 0.3, 0.3), 0.3, ior=1.6, distribution="blinn_phong")),
    "brushed aluminium, Ward α 0.08 × 0.3": ("conductor", S.ward("aluminium", 0.08, 0.3)),
    "brushed gold, Ward α 0.2 × 0.05": ("conductor", S.ward("gold", 0.2, 0.05)),
    "brushed copper, Ashikhmin-Shirley 200 × 20": ("conductor", S.ashikhmin_shirley("copper", 200.0, 20.0)),
    "brushed chrome, Ashikhmin-Shirley 1000 × 100": ("conductor", S.ashikhmin_shirley("chrome", 1000.0, 100.0)),
    "red satin, Lambert + Charlie sheen α 0.4": ("cloth", S.satin((0.3, 0.03, 0.05), (0.6, 0.3, 0.3), 0.4)),
    "blue satin, Lambert + Charlie sheen α 0.7": ("cloth", S.satin((0.05, 0.08, 0.3), (0.4, 0.5, 0.8), 0.7)),
}
# variant -> the material whose table loses cells
MISSING = {
    "gold, Beckmann α 0.2, cells missing": "gold, Beckmann α 0.2",
    "red plastic, Lambert under GGX α 0.1, cells missing": "red plastic, Lambert under GGX α 0.1",
}
UNNEEDED = {"conductor": ("clearcoat", "sheen"), "dielectric": ("metallic",), "cloth": ("metallic", "clearcoat")}
LOBES_ON = {"metallic": 0.05, "clearcoat": 0.01, "sheen": 0.01, "subsurface": 0.05}

# configurations: (label, pb.fit keywords; "weights": "solid_angle" for the cells' solid angles)
CONFIGURATIONS = [(f"{loss}, {method}", dict(loss=loss, method=method))
                  for method in pb.fitting.METHODS for loss in pb.fitting.LOSSES]
CONFIGURATIONS += [(f"{loss}, batched, solid angles", dict(loss=loss, weights="solid_angle"))
                   for loss in pb.fitting.LOSSES]
CONFIGURATIONS += [("scaled_log, batched, from a metal", dict(init={"metallic": 1.0})),
                   ("scaled_log, batched, every lobe kept", dict(select_lobes=False))]


AZIMUTHS = 16  # φh of an anisotropic material's table: its mean over [0, π) (period π)


def table_of(f):
    """The complete MERL table of f: of an anisotropic f, its mean over the half vector's
    azimuth, what a table of a sample turning about its normal holds."""
    anisotropic = isinstance(f, (S.Ward, S.AshikhminShirley))
    azimuths = (np.arange(AZIMUTHS) + 0.5) * (np.pi / AZIMUTHS) if anisotropic else [0.0]
    values = sum(np.asarray(f(*pb.measured.merl_pairs(phi_h))) for phi_h in azimuths) / len(azimuths)
    return pb.measured.MerlBRDF(values.T.reshape((3,) + pb.measured.MERL_SHAPE))


def without_cells(table, seed=11):
    """The table without the cells of θd < 2° and a quarter of the others, drawn at random."""
    values = table.table.copy()
    values[:, :, :2, :] = np.nan
    lost = np.random.default_rng(seed).random(pb.measured.MERL_SHAPE) < 0.25
    values[:, lost] = np.nan
    return pb.measured.MerlBRDF(values)


def _half_vector_nodes():
    """Nodes and weights over the hemisphere of half vectors: θh = (π/2) t², Gauss-Legendre
    in t on panels that crowd towards the normal (where a specular peak sits), φh uniform."""
    x, w = np.polynomial.legendre.leggauss(16)
    edges = [0.0, 0.05, 0.1, 0.2, 0.35, 0.55, 0.75, 1.0]
    t = np.concatenate([a + (b - a) * (x + 1) / 2 for a, b in zip(edges[:-1], edges[1:])])
    wt = np.concatenate([(b - a) / 2 * w for a, b in zip(edges[:-1], edges[1:])])
    theta = 0.5 * np.pi * t**2
    d_theta = np.pi * t * wt  # dθh = π t dt
    phi = (np.arange(128) + 0.5) * (2.0 * np.pi / 128)
    h = np.stack([np.outer(np.sin(theta), np.cos(phi)), np.outer(np.sin(theta), np.sin(phi)),
                  np.outer(np.cos(theta), np.ones_like(phi))], axis=-1).reshape(-1, 3)
    weights = np.outer(np.sin(theta) * d_theta, np.full(phi.shape, 2.0 * np.pi / 128)).reshape(-1)
    return h, weights


_H, _H_WEIGHTS = _half_vector_nodes()
_VIEWS_X, _VIEWS_W = np.polynomial.legendre.leggauss(8)  # over μo² in [0, 1]


def directional_albedo(f, wo):
    """∫ f(wi, wo) cos θl dωi (3,) over wi = reflect(wo, h): dωi = 4 (wo·h) dωh, missing data as 0."""
    cos_d = _H @ wo
    wi = 2.0 * cos_d[:, None] * _H - wo
    keep = (cos_d > 0.0) & (wi[:, 2] > 1e-9)
    wi = wi[keep] / np.linalg.norm(wi[keep], axis=-1, keepdims=True)
    values = np.nan_to_num(np.asarray(f(wi, np.broadcast_to(wo, wi.shape)), dtype=np.float64))
    return (values * (wi[:, 2] * 4.0 * cos_d[keep] * _H_WEIGHTS[keep])[:, None]).sum(axis=0)


def albedos(f):
    """(directional albedo at normal incidence, hemispherical albedo), RGB each: the second
    ∫ E(μo) 2 μo dμo, Gauss-Legendre in μo²."""
    normal = directional_albedo(f, np.array([0.0, 0.0, 1.0]))
    mu = np.sqrt(0.5 * (_VIEWS_X + 1.0))
    views = np.stack([np.sqrt(1.0 - mu**2), np.zeros_like(mu), mu], axis=-1)
    hemispherical = sum(0.5 * w * directional_albedo(f, wo) for w, wo in zip(_VIEWS_W, views))
    return normal, hemispherical


def solid_angle_weights():
    """Each coarse cell's share of the pair measure dωi dωo = 4 cos θd dωh dωd, times its stride."""
    sizes = np.array(pb.measured.MERL_SHAPE)
    i_h, i_d, i_p = (np.arange(n)[::s] + 0.5 for n, s in zip(sizes, MERL_STEP))
    theta_h = (i_h / 90.0) ** 2 * (np.pi / 2)
    d_theta_h = np.pi * i_h / 90.0**2 * MERL_STEP[0]  # θh = (π/2)(i/90)²
    theta_d = i_d / 90.0 * (np.pi / 2)
    cell = (np.sin(theta_h) * d_theta_h)[:, None, None] * (np.cos(theta_d) * np.sin(theta_d))[None, :, None]
    weights = np.broadcast_to(cell, (len(i_h), len(i_d), len(i_p))).reshape(-1)
    return weights / weights.mean()


def lobes_on(material):
    return {name: float(np.max(getattr(material, name))) for name, floor in LOBES_ON.items()
            if np.max(getattr(material, name)) > floor}


def pictures(brdf):
    return [render_sphere(brdf, RESOLUTION, environment=e, samples=SAMPLES, light_intensity=0.0)
            for e in ENVIRONMENTS]


def fitted_f(material):
    return lambda wi, wo: pb.reference.eval(material, wi, wo)


def measure_fit(result, data_albedos, data_pictures):
    """The figures of one fit against the complete table's."""
    material = result.material
    normal, hemispherical = albedos(fitted_f(material))
    fit_pictures = pictures(lambda wi, wo: pb.eval(material, wi.astype(np.float32), wo.astype(np.float32)))
    image = [float(np.linalg.norm(p - q) / np.linalg.norm(q)) for p, q in zip(fit_pictures, data_pictures)]
    return {"normal_albedo": float(np.max(np.abs(normal / data_albedos[0] - 1.0))),
            "hemispherical_albedo": float(np.max(np.abs(hemispherical / data_albedos[1] - 1.0))),
            "image": image, "lobes": lobes_on(material), "cost": float(result.cost)}


def cases(names=None):
    """(name, kind, the complete table, the table fitted) of each material (of ``names``)."""
    tables = {}
    for name, (kind, f) in MATERIALS.items():
        if names is None or name in names or any(MISSING[v] == name for v in names if v in MISSING):
            tables[name] = table_of(f)
            if names is None or name in names:
                yield name, kind, tables[name], tables[name]
    for name, source in MISSING.items():
        if names is None or name in names:
            yield name, MATERIALS[source][0], tables[source], without_cells(tables[source])


def run(configurations=CONFIGURATIONS, names=None, log=sys.stderr):
    wi, wo = pb.measured.merl_pairs(step=MERL_STEP)
    solid_angles = solid_angle_weights()
    results = {}
    for name, kind, complete, fitted in cases(names):
        data_albedos = albedos(lambda a, b: complete.eval(a, b, interpolation="linear"))
        data_pictures = pictures(complete)
        measured = fitted.values(step=MERL_STEP)
        results[name] = {"kind": kind, "fits": {}}
        for label, keywords in configurations:
            keywords = dict(keywords)
            if keywords.get("weights") == "solid_angle":
                keywords["weights"] = solid_angles
            start = time.perf_counter()
            result = pb.fit(wi, wo, measured, **keywords)
            seconds = time.perf_counter() - start
            figures = measure_fit(result, data_albedos, data_pictures)
            figures["seconds"] = seconds
            figures["unneeded"] = [lobe for lobe in UNNEEDED[kind] if lobe in figures["lobes"]]
            results[name]["fits"][label] = figures
            print(f"{name} | {label}: albedo {figures['normal_albedo']:.1%} / {figures['hemispherical_albedo']:.1%},"
                  f" image {figures['image'][0]:.1%} / {figures['image'][1]:.1%}, lobes {figures['lobes']}, "
                  f"{seconds:.2f} s", file=log, flush=True)
    return results


def summary_table(results):
    """Per configuration: median and worst albedo errors, median image error, lobes not needed."""
    labels = list(next(iter(results.values()))["fits"])
    lines = ["| fit | albedo at normal incidence, median / worst | hemispherical albedo, median / worst "
             "| image error (studio, outdoor), median / worst | lobes not needed | seconds a fit |",
             "|---|---|---|---|---|---|"]
    for label in labels:
        fits = [material["fits"][label] for material in results.values()]
        normal = [f["normal_albedo"] for f in fits]
        hemi = [f["hemispherical_albedo"] for f in fits]
        image = [np.mean(f["image"]) for f in fits]
        unneeded = sum(bool(f["unneeded"]) for f in fits)
        seconds = statistics.median(f["seconds"] for f in fits)
        lines.append(f"| {label} | {statistics.median(normal):.1%} / {max(normal):.1%} | "
                     f"{statistics.median(hemi):.1%} / {max(hemi):.1%} | "
                     f"{statistics.median(image):.1%} / {max(image):.1%} | {unneeded} of {len(fits)} | {seconds:.2f} |")
    return "\n".join(lines)


def material_table(results, label):
    """Per material, the figures of one configuration."""
    lines = [f"| measured ({label}) | albedo at normal incidence | hemispherical albedo | image error, studio / outdoor "
             "| lobes on |", "|---|---|---|---|---|"]
    for name, material in results.items():
        f = material["fits"][label]
        lobes = ", ".join(f"{k} {v:.2f}" for k, v in f["lobes"].items()) or "none"
        flag = " (not needed: " + ", ".join(f["unneeded"]) + ")" if f["unneeded"] else ""
        lines.append(f"| {name} | {f['normal_albedo']:.1%} | {f['hemispherical_albedo']:.1%} | "
                     f"{f['image'][0]:.1%} / {f['image'][1]:.1%} | {lobes}{flag} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--json", help="write every figure to this file")
    parser.add_argument("--only", nargs="*", help="configurations to run (labels; default all)")
    parser.add_argument("--materials", nargs="*", help="materials to run (names; default all)")
    args = parser.parse_args(argv)
    configurations = [c for c in CONFIGURATIONS if not args.only or c[0] in args.only]
    results = run(configurations, names=args.materials)
    if args.json:
        with open(args.json, "w") as out:
            json.dump(results, out, indent=1, ensure_ascii=False)
    print(summary_table(results))
    print()
    print(material_table(results, configurations[0][0]))


if __name__ == "__main__":
    main()
