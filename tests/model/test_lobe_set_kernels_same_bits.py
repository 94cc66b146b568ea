"""docs/performance.md: a material whose lobes are off runs a kernel compiled
without them (specular alone for metallic 1 without clearcoat; diffuse and
specular without sheen, subsurface and clearcoat), chosen once per call for a
uniform material and per batch, when all its lanes agree, for a per-element
one; `eval`, `eval_pdf` and `sample` have them. Such a kernel leaves out only terms that
are exactly 0, so its f must be the same bits as the full kernel's, which a
batch runs when one of its lanes has a clearcoat. With the energy compensation
the kernels take the lobe sets too: per element with the same bits again; a
uniform material's read the tables by its blended row, which rounds apart
from the per-element lookup of the full kernel here, so they agree to float32
roundings."""

import numpy as np
import pytest

import principled_brdf as pb
from conftest import MODELS, random_direction_pairs, seeded_rng

ISAS = pb.cpu_info()["available"]

MATERIALS = {
    # the specular alone (sheen and subsurface do not matter without a diffuse)
    "metal": dict(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3),
    "metal_with_dormant_lobes": dict(base_color=(0.5, 0.5, 0.6), metallic=1.0, roughness=0.7, anisotropic=0.8,
                                     sheen=1.0, subsurface=0.5, specular_tint=0.4),
    "mirror": dict(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.0),
    # diffuse and specular
    "plastic": dict(base_color=(0.2, 0.5, 0.8), metallic=0.3, roughness=0.45, anisotropic=0.5, specular=0.7,
                    specular_tint=0.3),
    "black_dielectric": dict(base_color=(0.0, 0.0, 0.0), roughness=0.9),
    # every lobe: the full kernel, also at the boundaries of the sets
    "almost_metal": dict(base_color=(0.9, 0.6, 0.3), metallic=float(np.float32(1.0) - np.float32(6e-8)),
                         roughness=0.3),
    "faint_clearcoat": dict(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3, clearcoat=1e-30),
    "faint_sheen": dict(base_color=(0.2, 0.5, 0.8), sheen=1e-30),
    "faint_subsurface": dict(base_color=(0.2, 0.5, 0.8), subsurface=1e-30),
    **{name: pb.presets.parameters(name) for name in pb.presets.names()},
}


@pytest.fixture(scope="module")
def pairs():
    rng = seeded_rng("lobe-sets")
    wi, wo = random_direction_pairs(rng, 4_099, grazing_fraction=0.2)  # a tail in every instruction set
    return wi.astype(np.float32), wo.astype(np.float32)


def beside_a_clearcoat(material: pb.Material, n: int) -> pb.Material:
    """2n elements per element: the material's at the even ones, with a clearcoat at the odd
    ones, so that no batch of any width has all its lanes in a smaller LobeSet (the elements
    are independent): the full kernel."""
    values = {k: np.broadcast_to(np.asarray(v, np.float64), (n, 3) if k == "base_color" else (n,))
              for k, v in material.as_dict().items()}
    breaker = {**values, "clearcoat": np.full(n, 0.5)}
    return pb.Material(**{k: np.stack([values[k], breaker[k]], axis=1).reshape((2 * n,) + values[k].shape[1:])
                          for k in values})


def full_kernel(material: pb.Material, wi: np.ndarray, wo: np.ndarray, evaluate=pb.eval, **options):
    """f (or `evaluate`'s result) by the full kernel (beside_a_clearcoat)."""
    result = evaluate(beside_a_clearcoat(material, len(wi)), np.repeat(wi, 2, axis=0), np.repeat(wo, 2, axis=0),
                      **options)
    if evaluate is pb.eval_pdf:
        return result.value[0::2], result.pdf[0::2]
    return result[0::2]


def bits(x: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(x).view(np.uint32)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_the_kernel_of_a_lobe_set_has_the_full_kernels_bits(pairs, isa, model, name):
    wi, wo = pairs
    material = pb.Material(**MATERIALS[name])
    for cosine in (False, True):
        expected = full_kernel(material, wi, wo, model=model, isa=isa, cosine=cosine)
        got = pb.eval(material, wi, wo, model=model, isa=isa, cosine=cosine)
        np.testing.assert_array_equal(bits(got), bits(expected), err_msg=f"{name} cosine={cosine}")
        assert np.all(np.isfinite(got))
        # f with the sampling pdf in one pass (eval_pdf) takes the same lobe sets
        value, pdf = full_kernel(material, wi, wo, evaluate=pb.eval_pdf, model=model, isa=isa, cosine=cosine)
        got_pair = pb.eval_pdf(material, wi, wo, model=model, isa=isa, cosine=cosine)
        np.testing.assert_array_equal(bits(got_pair.value), bits(value), err_msg=f"{name} cosine={cosine}")
        np.testing.assert_array_equal(bits(got_pair.pdf), bits(pdf), err_msg=f"{name} cosine={cosine}")
        np.testing.assert_array_equal(bits(got_pair.value), bits(got))
    rows = pb.eval(material, np.ascontiguousarray(wi.T), np.ascontiguousarray(wo.T), layout="soa", model=model,
                   isa=isa)
    np.testing.assert_array_equal(bits(rows.T), bits(full_kernel(material, wi, wo, model=model, isa=isa)))


def texture_of_runs(rng, n: int) -> pb.Material:
    """Per element: runs of one material (metal, plastic, a coated one) of random
    lengths, so that some batches agree on a smaller set and some straddle two."""
    names = ["metal", "plastic", "car_paint", "metal_with_dormant_lobes", "black_dielectric"]
    runs, total = [], 0
    while total < n:
        length = int(rng.integers(1, 70))
        runs.append((names[int(rng.integers(len(names)))], length))
        total += length
    choice = np.concatenate([[names.index(name)] * length for name, length in runs])[:n]
    tables = [pb.Material(**MATERIALS[name]).as_dict() for name in names]
    return pb.Material(**{k: np.array([table[k] for table in tables], np.float64)[choice] for k in tables[0]})


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
def test_a_textures_batches_take_their_lobe_set(pairs, isa, model):
    wi, wo = pairs
    texture = texture_of_runs(seeded_rng("lobe-sets-texture", isa, model), len(wi))
    for compensation in (False, True):  # per element, the compensated kernels read the same corners: the same bits
        options = dict(model=model, isa=isa, energy_compensation=compensation)
        got = pb.eval(texture, wi, wo, **options)
        np.testing.assert_array_equal(bits(got), bits(full_kernel(texture, wi, wo, **options)))
        value, pdf = full_kernel(texture, wi, wo, evaluate=pb.eval_pdf, **options)
        got_pair = pb.eval_pdf(texture, wi, wo, **options)
        np.testing.assert_array_equal(bits(got_pair.value), bits(value))
        np.testing.assert_array_equal(bits(got_pair.pdf), bits(pdf))


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
def test_the_compensated_kernels_of_the_lobe_sets_agree_with_the_full_kernel(pairs, isa, model):
    wi, wo = pairs
    for name in sorted(MATERIALS):
        material = pb.Material(**MATERIALS[name])
        options = dict(model=model, isa=isa, energy_compensation=True)
        expected = full_kernel(material, wi, wo, **options)
        got = pb.eval(material, wi, wo, **options)
        np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-30, err_msg=name)
        value, pdf = full_kernel(material, wi, wo, evaluate=pb.eval_pdf, **options)
        got_pair = pb.eval_pdf(material, wi, wo, **options)
        np.testing.assert_array_equal(bits(got_pair.value), bits(got), err_msg=name)
        np.testing.assert_allclose(got_pair.pdf, pdf, rtol=1e-5, atol=1e-30, err_msg=name)
        # and they differ from the single-scattering f where the lobe has energy to give back
        assert np.any(got > pb.eval(material, wi, wo, model=model, isa=isa) * (1 + 1e-4)) or material.roughness < 0.05


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
def test_sampling_by_a_lobe_set_gives_the_full_kernels_bits(pairs, isa, model):
    """A uniform material's samples come from its lobe set's pipelined loop; beside a
    coated material, per element, the same uniforms go through the full kernel."""
    _, wo = pairs
    n = len(wo)
    u = seeded_rng("lobe-sets-sampling", isa, model).random((n, 3)).astype(np.float32)
    for name in sorted(MATERIALS):
        material = pb.Material(**MATERIALS[name])
        for sampler in ("visible", "distribution"):
            options = dict(model=model, isa=isa, specular_sampler=sampler)
            full = pb.sample(beside_a_clearcoat(material, n), np.repeat(wo, 2, axis=0), u=np.repeat(u, 2, axis=0),
                             **options)
            got = pb.sample(material, wo, u=u, **options)
            rows = pb.sample(material, np.ascontiguousarray(wo.T), u=np.ascontiguousarray(u.T), layout="soa",
                             **options)
            for field in ("wi", "pdf", "weight", "lobe"):
                expected = getattr(full, field)[0::2]
                message = f"{name} {sampler} {field}"
                np.testing.assert_array_equal(bits(getattr(got, field)), bits(expected), err_msg=message)
                np.testing.assert_array_equal(bits(getattr(rows, field).T), bits(expected), err_msg=message)
            assert np.all(np.isfinite(got.weight)) and np.any(got.pdf > 0)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
def test_a_textures_samples_take_their_lobe_set(pairs, isa, model):
    _, wo = pairs
    n = len(wo)
    texture = texture_of_runs(seeded_rng("lobe-sets-texture-sampling", isa, model), n)
    u = seeded_rng("lobe-sets-texture-u", isa, model).random((n, 3)).astype(np.float32)
    full = pb.sample(beside_a_clearcoat(texture, n), np.repeat(wo, 2, axis=0), u=np.repeat(u, 2, axis=0), model=model,
                     isa=isa)
    got = pb.sample(texture, wo, u=u, model=model, isa=isa)
    for field in ("wi", "pdf", "weight", "lobe"):
        np.testing.assert_array_equal(bits(getattr(got, field)), bits(getattr(full, field)[0::2]), err_msg=field)
