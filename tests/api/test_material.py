"""Material: docs/model.md, "The model" defaults and domains, immutability, replace, mix; gamma22_to_linear."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
import numpy_model
import numpy_model_2015
from conftest import TABLE_DOMAINS, random_directions, random_material_arrays, random_material_dict, seeded_rng

# docs/model.md, "The model", copied from the table (not from the library)
# docs/model.md, "The model", and docs/model-2015.md, restated once in the independent transcriptions
TABLE_DEFAULTS = numpy_model.DEFAULTS | {name: numpy_model_2015.DEFAULTS[name] for name in ("spec_trans", "flatness", "diff_trans")}


# --------------------------------------------------------------------------
# defaults, table


def test_defaults_equal_spec():
    m = pb.Material()
    for name, value in TABLE_DEFAULTS.items():
        np.testing.assert_array_equal(getattr(m, name), np.asarray(value), err_msg=name)
    assert m.is_uniform and m.shape == ()
    assert m.base_color.shape == (3,) and m.roughness.shape == ()


def test_parameter_table_matches_spec():
    assert list(pb.PARAMETERS) == list(TABLE_DEFAULTS)  # the table order, snake_case
    for name, info in pb.PARAMETERS.items():
        assert np.array_equal(np.asarray(info.default), np.asarray(TABLE_DEFAULTS[name])), name
        assert (info.lower, info.upper) == TABLE_DOMAINS[name], name


def test_keyword_and_positional_construction_agree():
    assert pb.Material(*TABLE_DEFAULTS.values()) == pb.Material()
    assert pb.Material(roughness=0.25) == pb.Material(**dict(TABLE_DEFAULTS, roughness=0.25))


@pytest.mark.parametrize("name", list(TABLE_DOMAINS))
def test_domain_edges_are_accepted(name):
    lo, hi = TABLE_DOMAINS[name]
    for value in (lo, hi if np.isfinite(hi) else 1e6):
        arg = (value,) * 3 if name == "base_color" else value
        m = pb.Material(**{name: arg})
        assert np.all(getattr(m, name) == value)


def test_parameters_are_float64_arrays():
    m = pb.Material(roughness=1, metallic=np.float32(0.25), base_color=[1, 0, 0], anisotropic=True)
    for name in TABLE_DEFAULTS:
        assert isinstance(getattr(m, name), np.ndarray) and getattr(m, name).dtype == np.float64, name
    assert m.roughness == 1.0 and m.metallic == 0.25 and m.anisotropic == 1.0


# --------------------------------------------------------------------------
# repr


def test_repr_names_every_parameter_and_value():
    m = pb.Material(base_color=(0.9, 0.6, 0.2), metallic=1.0, roughness=0.35, clearcoat_gloss=0.25)
    text = repr(m)
    assert text.startswith("Material(")
    for name in TABLE_DEFAULTS:
        assert f"{name}=" in text, name
    for fragment in ("base_color=(0.9, 0.6, 0.2)", "metallic=1", "roughness=0.35", "clearcoat_gloss=0.25", "specular=0.5"):
        assert fragment in text, fragment


def test_repr_of_per_element_parameters_is_short_and_informative():
    roughness = np.linspace(0.1, 0.9, 1000).reshape(10, 100)
    m = pb.Material(roughness=roughness, base_color=np.full((10, 100, 3), 0.5))
    text = repr(m)
    assert len(text) < 600
    assert "roughness=" in text and "(10, 100)" in text and "0.1" in text and "0.9" in text
    assert "base_color=" in text and "(10, 100, 3)" in text


# --------------------------------------------------------------------------
# immutability, aliasing


def test_attributes_cannot_be_set_or_deleted():
    m = pb.Material()
    with pytest.raises(AttributeError):
        m.roughness = 0.1
    with pytest.raises(AttributeError):
        m.new_attribute = 1
    with pytest.raises(AttributeError):
        del m.roughness
    assert m.roughness == 0.5


def test_parameter_arrays_are_read_only():
    m = pb.Material(roughness=np.array([0.1, 0.2]))
    with pytest.raises(ValueError):
        m.roughness[0] = 0.9
    with pytest.raises(ValueError):
        m.base_color[0] = 0.0
    assert m.roughness[0] == 0.1


def test_material_does_not_alias_the_callers_arrays():
    roughness = np.array([0.1, 0.2, 0.3])
    color = np.array([[0.5, 0.5, 0.5]] * 3)
    m = pb.Material(roughness=roughness, base_color=color)
    roughness[0] = 0.9
    color[0, 0] = 0.0
    assert m.roughness[0] == 0.1 and m.base_color[0, 0] == 0.5
    # and the caller's arrays stay writeable
    roughness[1] = 0.0


def test_material_is_not_hashable_but_comparable():
    assert pb.Material() == pb.Material()
    assert pb.Material(roughness=0.2) != pb.Material()
    assert pb.Material() != "Material()"
    with pytest.raises(TypeError):
        hash(pb.Material())


# --------------------------------------------------------------------------
# replace


def test_replace_changes_only_the_named_parameters():
    rng = seeded_rng("replace")
    params = random_material_dict(rng)
    a = pb.Material(**params)
    b = a.replace(roughness=0.125, base_color=(0.1, 0.2, 0.3))
    assert a == pb.Material(**params)  # a unchanged
    for name in params:  # (the 2015 parameters stay at their defaults)
        expected = {"roughness": 0.125, "base_color": (0.1, 0.2, 0.3)}.get(name, params[name])
        np.testing.assert_array_equal(getattr(b, name), np.asarray(expected), err_msg=name)
    assert a.replace() == a and a.replace() is not a


def test_replace_with_per_element_values_and_validation():
    a = pb.Material()
    b = a.replace(roughness=np.array([0.0, 0.5, 1.0]))
    assert b.shape == (3,)
    with pytest.raises(ValueError, match=r"roughness\[1\]"):
        a.replace(roughness=[0.0, -1.0])
    with pytest.raises(TypeError, match="rougness"):
        a.replace(rougness=0.1)


def test_as_dict_round_trips():
    m = pb.Material(**random_material_arrays(seeded_rng("as_dict"), 7))
    d = m.as_dict()
    assert list(d) == list(TABLE_DEFAULTS)
    assert pb.Material(**d) == m


# --------------------------------------------------------------------------
# per-element shapes


def test_per_element_shapes():
    roughness = np.zeros((4, 5))
    color = np.ones((4, 5, 3))
    m = pb.Material(roughness=roughness, base_color=color, metallic=np.zeros((1, 5)))
    assert m.shape == (4, 5) and not m.is_uniform
    assert pb.Material(base_color=np.ones((7, 3))).shape == (7,)
    assert pb.Material(sheen=np.ones((2, 1)), clearcoat=np.ones(3)).shape == (2, 3)


# --------------------------------------------------------------------------
# mix


def _two_materials(seed):
    rng = seeded_rng("mix", seed)
    return random_material_dict(rng), random_material_dict(rng)


@pytest.mark.parametrize("t", [0.0, 0.25, 0.5, 0.8, 1.0])
def test_mix_interpolates_every_parameter(t):
    pa, pb_ = _two_materials(t)
    mixed = pb.Material.mix(pb.Material(**pa), pb.Material(**pb_), t)
    assert isinstance(mixed, pb.Material)
    for name in pa:
        a, b = np.asarray(pa[name]), np.asarray(pb_[name])
        np.testing.assert_allclose(getattr(mixed, name), a + (b - a) * t, rtol=1e-15, atol=1e-300, err_msg=name)
    if t == 0.0:
        assert mixed == pb.Material(**pa)


def test_mix_endpoints_are_exact_for_t_one_when_representable():
    a = pb.Material(roughness=0.25, base_color=(0.5, 0.25, 1.0), metallic=0.0)
    b = pb.Material(roughness=0.75, base_color=(1.0, 0.5, 0.0), metallic=1.0)
    assert pb.Material.mix(a, b, 1.0) == b
    assert pb.Material.mix(a, b, 0.0) == a


def test_mix_with_a_per_element_mask():
    # a (H, W) mask mixing two uniform materials gives per-element parameters
    # of shape (H, W) and base_color (H, W, 3)
    rng = seeded_rng("mask")
    pa, pb_ = _two_materials("mask")
    mask = rng.uniform(0.0, 1.0, (6, 9))
    mask[0, 0], mask[0, 1] = 0.0, 1.0
    mixed = pb.Material.mix(pb.Material(**pa), pb.Material(**pb_), mask)
    assert mixed.shape == (6, 9)
    assert mixed.base_color.shape == (6, 9, 3)
    for name in pa:
        if name == "base_color":
            expected = np.asarray(pa[name]) + (np.asarray(pb_[name]) - np.asarray(pa[name])) * mask[..., None]
        else:
            expected = pa[name] + (pb_[name] - pa[name]) * mask
            assert getattr(mixed, name).shape == (6, 9), name
        np.testing.assert_allclose(getattr(mixed, name), expected, rtol=1e-15, atol=1e-300, err_msg=name)
    # the binary pixels evaluate exactly like the endpoint materials
    wi = random_directions(rng, 1)[0]
    wo = random_directions(rng, 1)[0]
    f = pb.reference.eval(mixed, wi, wo)
    assert f.shape == (6, 9, 3)
    np.testing.assert_array_equal(f[0, 0], pb.reference.eval(pb.Material(**pa), wi, wo))
    np.testing.assert_allclose(f[0, 1], pb.reference.eval(pb.Material(**pb_), wi, wo), rtol=1e-13)


def test_mix_of_per_element_materials_broadcasts():
    rng = seeded_rng("mix_per_element")
    a = pb.Material(**random_material_arrays(rng, 5))
    b = pb.Material(roughness=0.3)
    mask = np.linspace(0.0, 1.0, 5)
    mixed = pb.Material.mix(a, b, mask)
    assert mixed.shape == (5,)
    np.testing.assert_allclose(mixed.roughness, a.roughness + (0.3 - a.roughness) * mask, rtol=1e-15)
    # a (2, 1) mask against (5,) materials broadcasts to (2, 5)
    assert pb.Material.mix(a, b, mask.reshape(5)[None, :].repeat(2, 0)).shape == (2, 5)
    assert pb.Material.mix(a, b, np.array([[0.0], [1.0]])).shape == (2, 5)


def test_mix_result_stays_in_the_domains():
    rng = seeded_rng("mix_domains")
    for _ in range(20):
        pa, pb_ = random_material_dict(rng), random_material_dict(rng)
        mixed = pb.Material.mix(pb.Material(**pa), pb.Material(**pb_), rng.uniform(0, 1, 50))
        for name, (lo, hi) in TABLE_DOMAINS.items():
            value = getattr(mixed, name)
            assert np.all(value >= lo) and np.all(value <= hi), name


# --------------------------------------------------------------------------
# gamma22_to_linear


def test_gamma22_to_linear_is_c_to_the_2_2():
    rng = seeded_rng("gamma")
    colors = rng.uniform(0.0, 1.0, (100, 3))
    colors[0] = (0.0, 1.0, 0.5)
    np.testing.assert_allclose(pb.gamma22_to_linear(colors), colors**2.2, rtol=1e-15, atol=0)
    assert pb.gamma22_to_linear(colors).shape == (100, 3)
    assert float(pb.gamma22_to_linear(0.5)) == pytest.approx(0.5**2.2, rel=1e-15)
    np.testing.assert_allclose(
        pb.gamma22_to_linear((0.82, 0.67, 0.16)), np.array([0.82, 0.67, 0.16]) ** 2.2, rtol=1e-15
    )
    # values above 1 are allowed (>= 0 each)
    assert pb.gamma22_to_linear(2.0) == pytest.approx(2.0**2.2, rel=1e-15)


def test_gamma22_to_linear_is_not_applied_implicitly():
    # docs/model.md, "The model": base_color is linear; mon2lin is a helper, not a hidden step
    m = pb.Material(base_color=(0.5, 0.5, 0.5))
    np.testing.assert_array_equal(m.base_color, [0.5, 0.5, 0.5])
    n = np.array([0.0, 0.0, 1.0])
    f = pb.reference.eval_lobes(m, n, n).diffuse
    np.testing.assert_allclose(f, 0.5 / np.pi, rtol=1e-14)


def test_gamma22_to_linear_rejects_bad_colors():
    with pytest.raises(ValueError, match=r"color\[1\]"):
        pb.gamma22_to_linear([0.5, -0.1, 0.2])
    with pytest.raises(ValueError, match=r"color\[2\]"):
        pb.gamma22_to_linear([0.5, 0.1, np.nan])
    with pytest.raises(TypeError, match="color"):
        pb.gamma22_to_linear("red")


def test_material_pickles_for_multiprocessing():
    import pickle

    m = pb.Material(roughness=np.array([0.1, 0.9]), base_color=(0.2, 0.3, 0.4), clearcoat=1.0)
    copy = pickle.loads(pickle.dumps(m))
    assert copy == m and copy.shape == (2,)
