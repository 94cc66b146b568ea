"""The energy compensation of the 2015 solid's rough dielectric (Kulla & Conty
2017; docs/energy-compensation.md, "The rough dielectric").

- the tables (written by scripts/dielectric_energy_tables.py): entries
  recomputed by the generator's quadrature, and the interpolated 1 - E against
  the whole-sphere quadrature of the float64 reference between the nodes;
- the white furnace over the whole sphere by quadrature of eval (not the
  tables): 1 within 2e-3 from both sides, roughness 0.05 to 1, η 1.01 to 4;
  the metal part's furnace likewise; pb.albedo's Monte Carlo agrees;
- generalised reciprocity in float64, f >= 0, nothing added as roughness -> 0,
  coloured glass never above the white glass's albedo;
- the reference against the independent transcription
  (tests/numpy_compensation_2015.py), the kernels against the reference on
  every instruction set here, sampling (the pdf of each draw, chi-square over
  the sphere), the derivatives against central differences;
- off: the same bits as without the keyword; the thin sheet refuses it.
"""

from __future__ import annotations

import pathlib
import sys

import numpy as np
import pytest

import principled_brdf as pb
import chi_square as cs
import numpy_compensation_2015 as transcription
import numpy_model_2015
import whole_sphere_albedo
from conftest import seeded_rng

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import dielectric_energy_tables as generator  # noqa: E402  (the tables' quadrature)

ISAS = pb.cpu_info()["available"]
FURNACE_BOUND = 2e-3
# η = 1.01 from inside: the edge of total internal reflection at μc = 0.14 and the tables'
# cells near η = 1, where the inside's albedo changes fastest (docs/energy-compensation.md)
FURNACE_BOUND_NEAR_ONE = 3.5e-3


def white_glass(roughness, eta, **more):
    return pb.Material(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=roughness, ior=eta, **more)


def whole_sphere(material, mu, eta, mode="importance", compensated=True):
    """(reflected, transmitted) over the whole sphere at cos θo = μ (negative: from inside), by
    quadrature of eval: the single-scattering lobes over the microfacet normals
    (whole_sphere_albedo.py), the added lobes (smooth, cosine-shaped) over wi in each hemisphere."""
    wo = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])

    def f(wi, v):
        return pb.reference.eval(material, wi, v, model="disney2015", mode=mode)

    reflected, transmitted = whole_sphere_albedo.albedo(f, wo, eta)
    if not compensated:
        return reflected, transmitted
    for side in (1.0, -1.0):  # Gauss-Legendre in cos θ, uniform in φ
        x, w = np.polynomial.legendre.leggauss(96)
        cos = (x + 1.0) / 2.0
        phi = (np.arange(32) + 0.5) * (2.0 * np.pi / 32)
        sin = np.sqrt(1.0 - cos * cos)
        wi = np.stack([np.outer(sin, np.cos(phi)), np.outer(sin, np.sin(phi)), np.outer(side * cos, np.ones_like(phi))],
                      axis=-1).reshape(-1, 3)
        added = pb.reference.eval_lobes(material, wi, np.broadcast_to(wo, wi.shape), model="disney2015", mode=mode,
                                        energy_compensation=True).multiple_scattering
        weights = np.outer(w / 2.0 * cos, np.full(phi.shape, 2.0 * np.pi / 32)).reshape(-1)
        part = (added * weights[:, None]).sum(axis=0)
        if side * mu > 0:
            reflected = reflected + part
        else:
            transmitted = transmitted + part
    return reflected, transmitted


def sphere_directions(rng, n):
    w = rng.normal(size=(n, 3))
    return w / np.linalg.norm(w, axis=1, keepdims=True)


def random_solid(rng, n):
    """Per-element 2015 solids over their domains (η up to 4 through specular)."""
    return pb.Material(base_color=rng.uniform(0, 1, (n, 3)), metallic=np.where(rng.random(n) < 0.3, 0.0, rng.random(n)),
                       specular=rng.uniform(0, 4.5, n), specular_tint=rng.random(n), roughness=rng.uniform(0, 1, n),
                       anisotropic=np.where(rng.random(n) < 0.5, 0.0, rng.random(n)), sheen=rng.random(n),
                       clearcoat=np.where(rng.random(n) < 0.5, 0.0, rng.random(n)), spec_trans=rng.random(n),
                       flatness=rng.random(n))


# ---------------------------------------------------------------- the tables

@pytest.mark.parametrize("side, x_index, r_index, mu_index", [(0, 4, 10, 0), (1, 8, 20, 48), (1, 16, 32, 20),
                                                              (0, 12, 5, 64), (1, 2, 28, 58)])
def test_table_entries_are_the_generators_quadrature(side, x_index, r_index, mu_index):
    tables = transcription.tables()
    eta = generator.eta_of_x(generator.x_nodes()[x_index])
    nodes = generator.cosine_nodes() if side == 0 else generator.inside_cosine_nodes(eta)
    mu, roughness = nodes[mu_index], generator.roughness_nodes()[r_index]
    e = generator.albedo(mu, roughness, eta if side == 0 else 1.0 / eta)
    assert abs((1.0 - e) - tables["interface"][side, x_index, r_index, mu_index]) < 1e-6


@pytest.mark.parametrize("mu, roughness, eta", [(0.83, 0.41, 1.33), (-0.47, 0.77, 1.5), (-0.93, 0.29, 2.2),
                                                (0.12, 0.95, 3.1), (-0.2, 0.55, 1.05), (0.6, 0.18, 3.9)])
def test_interpolated_tables_against_the_reference_between_the_nodes(mu, roughness, eta):
    """1 - E read from the tables at points between every node against the whole-sphere
    quadrature of the float64 reference itself (the model, not the generator's formula)."""
    reflected, transmitted = whole_sphere(white_glass(roughness, eta), mu, eta, compensated=False)
    side = int(mu < 0)
    table = transcription.interface_missing(side, np.array([abs(mu)]), np.array([roughness]), np.array([eta]))[0]
    assert abs((1.0 - reflected[0] - transmitted[0]) - table) < 1.2e-3


def test_metal_table_is_the_2015_specular_of_a_white_metal():
    metal = pb.Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.7)
    for mu in (0.95, 0.4, 0.08):
        reflected, transmitted = whole_sphere(metal, mu, 1.5, compensated=False)
        table = transcription.conductor_missing(np.array([mu]), np.array([0.7]))[0]
        assert transmitted[0] == 0.0 and abs((1.0 - reflected[0]) - table) < 1e-3


# ---------------------------------------------------------------- the white furnace

FURNACE = [(r, eta, mu) for r in (0.05, 0.3, 0.6, 1.0) for eta in (1.01, 1.5, 2.4, 4.0)
           for mu in (0.98, 0.5, 0.12, -0.12, -0.5, -0.98)]


@pytest.mark.parametrize("roughness, eta", sorted({(r, e) for r, e, _ in FURNACE}))
def test_white_furnace_over_the_whole_sphere(roughness, eta):
    glass = white_glass(roughness, eta)
    for mu in sorted({m for r, e, m in FURNACE if (r, e) == (roughness, eta)}):
        reflected, transmitted = whole_sphere(glass, mu, eta)
        total = reflected + transmitted
        bound = FURNACE_BOUND_NEAR_ONE if eta < 1.02 else FURNACE_BOUND
        assert np.all(np.abs(total - 1.0) < bound), (roughness, eta, mu, total)


def test_without_compensation_rough_glass_loses_light():
    reflected, transmitted = whole_sphere(white_glass(1.0, 1.5), -0.5, 1.5, compensated=False)
    assert (reflected + transmitted)[0] < 0.5


def test_metal_part_furnace():
    for roughness in (0.3, 1.0):
        metal = pb.Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=roughness)
        for mu in (0.9, 0.3):
            reflected, transmitted = whole_sphere(metal, mu, 1.5)
            assert np.all(np.abs(reflected - 1.0) < FURNACE_BOUND) and np.all(transmitted == 0.0)


def test_albedo_by_monte_carlo_is_one_from_either_side():
    glass = pb.Material(base_color=(1, 1, 1), ior=1.5, spec_trans=1, roughness=1)
    estimate = pb.albedo(glass, [0.9, 0.3, -0.3, -0.9], samples=1 << 20, model="disney2015", mode="importance",
                         energy_compensation=True)
    error = np.abs(estimate.total - 1.0)
    assert np.all(error < FURNACE_BOUND + 4.0 * estimate.total_error), (estimate.total, estimate.total_error)


# ---------------------------------------------------------------- properties

@pytest.fixture(scope="module")
def triples():
    rng = seeded_rng("dielectric compensation", "triples")
    n = 60_000
    return random_solid(rng, n), sphere_directions(rng, n), sphere_directions(rng, n)


@pytest.mark.parametrize("mode", ("radiance", "importance"))
def test_reference_matches_the_transcription(triples, mode):
    material, wi, wo = triples
    lobes = pb.reference.eval_lobes(material, wi, wo, model="disney2015", mode=mode, energy_compensation=True)
    params = {name: np.asarray(getattr(material, name), float) for name in numpy_model_2015.DEFAULTS
              if name != "diff_trans"}
    expected = transcription.multiple_scattering(params, wi, wo, mode)
    assert np.any(expected > 0.01)
    np.testing.assert_allclose(lobes.multiple_scattering, expected, rtol=1e-10, atol=1e-13)
    plain = pb.reference.eval_lobes(material, wi, wo, model="disney2015", mode=mode)
    for name in ("diffuse", "sheen", "specular", "clearcoat", "transmission"):
        np.testing.assert_array_equal(getattr(lobes, name), getattr(plain, name))
    np.testing.assert_allclose(lobes.total(), plain.total() + expected, rtol=1e-10, atol=1e-13)


def test_generalised_reciprocity(triples):
    """f(wi, wo) / n(wo)² = f(wo, wi) / n(wi)² in radiance mode, n the index on each side."""
    material, wi, wo = triples
    eta = numpy_model_2015.eta_of_specular(np.asarray(material.specular, float))

    def f(a, b):
        return pb.reference.eval_lobes(material, a, b, model="disney2015", energy_compensation=True).multiple_scattering

    n_wi, n_wo = np.where(wi[:, 2] < 0, eta, 1.0), np.where(wo[:, 2] < 0, eta, 1.0)
    forward, backward = f(wi, wo) / n_wo[:, None] ** 2, f(wo, wi) / n_wi[:, None] ** 2
    assert np.any(forward[wi[:, 2] * wo[:, 2] < 0] > 0)
    np.testing.assert_allclose(forward, backward, rtol=1e-6, atol=1e-14)


def test_nonnegative_and_finite(triples):
    material, wi, wo = triples
    f = pb.reference.eval(material, wi, wo, model="disney2015", energy_compensation=True)
    assert np.all(np.isfinite(f)) and np.all(f >= 0.0)


def test_nothing_added_as_roughness_vanishes():
    for mu in (0.9, 0.2, -0.2, -0.9):
        for roughness in (0.0, 0.02):
            reflected, transmitted = whole_sphere(white_glass(roughness, 1.5), mu, 1.5)
            plain = whole_sphere(white_glass(roughness, 1.5), mu, 1.5, compensated=False)
            assert abs((reflected + transmitted - plain[0] - plain[1])[0]) < 1e-4


def test_coloured_glass_never_above_the_white():
    for color in ((0.9, 0.5, 0.2), (0.2, 0.8, 1.0)):
        for mu in (0.7, -0.4):
            tinted = sum(whole_sphere(white_glass(0.8, 1.5).replace(base_color=color), mu, 1.5))
            white = sum(whole_sphere(white_glass(0.8, 1.5), mu, 1.5))
            assert np.all(tinted <= white + 1e-12)


def test_off_is_the_same_bits_and_the_sheet_refuses():
    rng = seeded_rng("dielectric compensation", "off")
    material = random_solid(rng, 4096)
    wi, wo = (sphere_directions(rng, 4096).astype(np.float32) for _ in range(2))
    np.testing.assert_array_equal(pb.eval(material, wi, wo, model="disney2015"),
                                  pb.eval(material, wi, wo, model="disney2015", energy_compensation=False))
    with pytest.raises(ValueError, match="energy_compensation: not available"):
        pb.eval(material, wi, wo, model="disney2015_thin", energy_compensation=True)


# ---------------------------------------------------------------- the kernels

@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("mode", ("radiance", "importance"))
def test_simd_matches_the_reference(triples, isa, mode):
    material, wi, wo = triples
    m32 = pb.Material(**{name: np.asarray(getattr(material, name), np.float32) for name in pb.PARAMETERS})
    wi32, wo32 = wi.astype(np.float32), wo.astype(np.float32)
    wi64, wo64 = wi32.astype(np.float64), wo32.astype(np.float64)
    reference = pb.reference.eval_lobes(m32, wi64, wo64, model="disney2015", mode=mode, energy_compensation=True)
    simd = pb.eval_lobes(m32, wi32, wo32, model="disney2015", mode=mode, isa=isa, energy_compensation=True)
    for name, ours, theirs in (("multiple_scattering", simd.multiple_scattering, reference.multiple_scattering),
                               ("total", pb.eval(m32, wi32, wo32, model="disney2015", mode=mode, isa=isa,
                                                 energy_compensation=True), reference.total())):
        errors = np.abs(ours - theirs) / np.maximum(np.abs(theirs), 1e-6)
        if name == "total":  # the single-scattering transmission near the critical angle: test_bsdf2015's bound
            errors = errors[np.all(reference.transmission == 0, axis=-1)]
        assert np.percentile(errors, 99.99) <= 1e-4, (isa, name, np.percentile(errors, 99.99))
        assert errors.max() <= 1e-3, (isa, name, errors.max())
    uniform = white_glass(0.6, 1.7)
    np.testing.assert_allclose(pb.eval(uniform, wi32, wo32, model="disney2015", isa=isa, energy_compensation=True),
                               pb.reference.eval(uniform, wi64, wo64, model="disney2015", energy_compensation=True),
                               rtol=2e-4, atol=1e-6)


def test_pdf_is_each_draws_and_weights_are_f_cos_over_pdf():
    rng = seeded_rng("dielectric compensation", "sample")
    n = 40_000
    material = random_solid(rng, n)
    wo = sphere_directions(rng, n)
    u = rng.random((n, 3))
    drawn = pb.reference.sample(material, wo, u, model="disney2015", energy_compensation=True)
    valid = drawn.pdf > 0
    assert np.any(valid & (drawn.lobe == 4)) and np.any(valid & (drawn.lobe == 0) & (wo[:, 2] < 0))
    pdf = pb.reference.pdf(material[valid], drawn.wi[valid], wo[valid], model="disney2015", energy_compensation=True)
    np.testing.assert_allclose(drawn.pdf[valid], pdf, rtol=1e-12)
    f = pb.reference.eval(material[valid], drawn.wi[valid], wo[valid], model="disney2015", energy_compensation=True)
    np.testing.assert_allclose(drawn.weight[valid], f * np.abs(drawn.wi[valid, 2:3]) / drawn.pdf[valid, None],
                               rtol=1e-12, atol=0)
    m32, wo32, u32 = material, wo.astype(np.float32), u.astype(np.float32)
    for isa in ISAS:
        simd = pb.sample(m32, wo32, u=u32, model="disney2015", isa=isa, energy_compensation=True)
        assert (simd.lobe == drawn.lobe).mean() > 0.999, isa
        close = (simd.lobe == drawn.lobe) & valid & (drawn.pdf > 1e-3)
        assert np.percentile(np.abs(simd.pdf[close] / drawn.pdf[close] - 1), 99) < 1e-3, isa


CHI_SQUARE_VIEWS = (0.7, 0.15, -0.3, -0.85)


@pytest.mark.parametrize("mu", CHI_SQUARE_VIEWS)
def test_sampling_chi_square_over_the_sphere(mu):
    """Draws from the compensated mixture (rough glass with some metal: the added lobes
    large on both sides) against pdf() integrated over the cells of the sphere."""
    glass = pb.Material(base_color=(0.9, 0.8, 0.7), spec_trans=0.85, metallic=0.1, roughness=0.8, ior=1.6)
    wo = np.array([np.sqrt(1 - mu * mu) * np.cos(0.3), np.sqrt(1 - mu * mu) * np.sin(0.3), mu])
    u = seeded_rng("dielectric compensation", "chi-square", mu).random((200_000, 3))
    drawn = pb.reference.sample(glass, wo, u, model="disney2015", energy_compensation=True)
    assert np.mean(drawn.lobe == 4) > 0.02  # the added transmission is drawn
    result = cs.chi_square_test(
        drawn.wi, lambda w: pb.reference.pdf(glass, w, wo, model="disney2015", energy_compensation=True),
        sphere=True, invalid=drawn.pdf == 0, cos_breaks=[-wo[2], -wo[2] / 1.6, -wo[2] * 1.6])
    assert result.p_value > cs.sidak_threshold(len(CHI_SQUARE_VIEWS)), result.describe()


# ---------------------------------------------------------------- the derivatives

def test_gradients_against_central_differences():
    rng = seeded_rng("dielectric compensation", "gradient")
    n = 300
    base = dict(base_color=rng.uniform(0.2, 0.9, (n, 3)), metallic=rng.uniform(0.05, 0.5, n),
                specular=rng.uniform(0.2, 3.0, n), roughness=rng.uniform(0.1, 0.95, n),
                spec_trans=rng.uniform(0.3, 0.95, n), anisotropic=rng.uniform(0.0, 0.6, n))
    material = pb.Material(**base)
    wi, wo = sphere_directions(rng, n), sphere_directions(rng, n)
    gradient = pb.reference.eval_grad(material, wi, wo, model="disney2015", energy_compensation=True,
                                      wrt=["metallic", "specular", "roughness", "spec_trans", "base_color", "wi", "wo"])
    step = 1e-6

    def f(m, a=wi, b=wo):
        return pb.reference.eval(m, a, b, model="disney2015", energy_compensation=True)

    columns = dict(zip(gradient.names, np.moveaxis(gradient.jacobian, -1, 0)))

    def agree(analytic, numeric, name):
        """Within 2e-4 but where the difference straddles a table node, where the interpolant's
        derivative jumps (a few elements in a thousand)."""
        close = np.isclose(analytic, numeric, rtol=2e-4, atol=2e-5).all(axis=-1)
        assert close.mean() > 0.99, (name, close.mean())

    for name in ("metallic", "specular", "roughness", "spec_trans"):
        value = np.asarray(base[name])
        numeric = (f(material.replace(**{name: value + step})) - f(material.replace(**{name: value - step}))) / (2 * step)
        agree(columns[name], numeric, name)
    for k, axis in enumerate("xyz"):
        shift = np.zeros(3)
        shift[k] = step
        agree(columns[f"wi_{axis}"], (f(material, wi + shift) - f(material, wi - shift)) / (2 * step), f"wi_{axis}")
    for isa in ISAS:
        simd = pb.eval_grad(material, wi.astype(np.float32), wo.astype(np.float32), model="disney2015", isa=isa,
                            energy_compensation=True, wrt=["roughness", "specular", "wo"])
        expected = pb.reference.eval_grad(material, wi, wo, model="disney2015", energy_compensation=True,
                                          wrt=["roughness", "specular", "wo"])
        scale = np.maximum(np.abs(expected.jacobian).max(axis=-1, keepdims=True), 1e-3)
        assert np.percentile(np.abs(simd.jacobian - expected.jacobian) / scale, 99) < 1e-3, isa
