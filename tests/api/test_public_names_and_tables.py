"""Each public module shows its public names only, and the tables of the C++ side
(models, lobes, samplers, parameters) are the ones every Python part uses."""

import importlib
import types

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _core

PUBLIC_MODULES = [pb, pb.reference, pb.microfacet, pb.plot, pb.render, pb.presets, pb.environment,
                  pb.procedural_environments, pb.piecewise,
                  importlib.import_module("principled_brdf.distributed")]
# names a module may use in its signatures without exporting them: the package's own
TOP_LEVEL = set(pb.__all__)
# every packed slot's name, base_color's three as base_color_r, _g, _b
SLOT_NAMES = tuple(name for row in _core.PARAMETER_TABLE
                   for name in ([f"{row[0]}_{c}" for c in "rgb"] if row[2] == 3 else [row[0]]))


@pytest.mark.parametrize("module", PUBLIC_MODULES, ids=lambda m: m.__name__)
def test_public_modules_show_only_their_public_names(module):
    assert hasattr(module, "__all__")
    for name in dir(module):
        value = getattr(module, name)
        if name.startswith("_") or name == "annotations" or isinstance(value, types.ModuleType):
            continue
        assert name in module.__all__ or name in TOP_LEVEL, f"{module.__name__}.{name} is neither public nor private"
    for name in module.__all__:
        assert hasattr(module, name)


def test_one_table_per_fact():
    assert pb.Lobes._fields == tuple(_core.LOBE_NAMES) == pb.reference.Lobes._fields
    assert tuple(pb.PARAMETERS) == tuple(row[0] for row in _core.PARAMETER_TABLE)
    for name, index in zip(_core.MODEL_NAMES, range(len(_core.MODEL_NAMES))):
        pb.eval(pb.Material(), np.float32([0, 0, 1]), np.float32([0, 0, 1]), model=name)
        assert pb._validate.MODELS[name] == index
    assert tuple(pb._validate.SAMPLERS) == tuple(_core.SAMPLER_NAMES) == ("visible", "distribution")
    assert tuple(_core.SAMPLED_LOBE_NAMES) == ("cosine", "specular", "clearcoat", "transmission", "diffuse_transmission")
    # the reference's defaults are the table's
    m = pb.Material()
    np.testing.assert_array_equal(pb.reference.eval(m, [0.6, 0, 0.8], [0, 0, 1]),
                                  pb.reference.eval(pb.Material(**{n: p.default for n, p in pb.PARAMETERS.items()}),
                                                    [0.6, 0, 0.8], [0, 0, 1]))


def test_albedo_lobes_come_from_the_sampler_in_one_pass():
    m = pb.presets.get("car_paint")
    wo = np.float32([0.5, 0.0, 0.8660254])
    drawn, shares = pb.sample(m, np.broadcast_to(wo, (4096, 3)), seed=3, with_lobes=True)
    np.testing.assert_allclose(shares.total(), drawn.weight, rtol=2e-6, atol=1e-7)
    again = pb.sample(m, np.broadcast_to(wo, (4096, 3)), seed=3)
    np.testing.assert_array_equal(drawn.weight, again.weight)
    # each share is that lobe's value cos θl / pdf
    f = pb.eval_lobes(m, drawn.wi, wo, cosine=True, check=False)
    valid = drawn.pdf > 0
    for share, lobe in zip(shares, f):
        np.testing.assert_allclose(share[valid], (lobe[valid] / drawn.pdf[valid, None]), rtol=3e-6, atol=1e-12)
        assert np.all(share[~valid] == 0)


def test_the_model_rules_are_what_each_model_does():
    """One table of every model's rules (_models, from the extension's MODEL_TABLE), and each
    model keeps them: the lobes it makes and draws, the sphere it covers, the parameters it
    refuses away from their defaults, energy compensation and the largest specular."""
    from principled_brdf import _models

    assert tuple(_models.RULES) == tuple(_core.MODEL_NAMES)
    for row in _core.MODEL_TABLE:  # the rules are the C++ table's rows
        rules = _models.RULES[row["name"]]._asdict()
        assert {key: rules[key] for key in row} == row
    rng = np.random.default_rng(20240518)
    sphere = rng.normal(size=(4096, 3))
    sphere /= np.linalg.norm(sphere, axis=-1, keepdims=True)
    for name, rules in _models.RULES.items():
        assert set(rules.reads) | set(rules.unread) == set(pb.PARAMETERS) and not set(rules.reads) & set(rules.unread)
        assert _models.gradient_names(name) == SLOT_NAMES[:rules.gradient_slots]
        material = pb.Material(**{p: min(0.5, pb.PARAMETERS[p].upper) for p in rules.reads if p != "base_color"},
                               base_color=(0.8, 0.5, 0.3))
        wo = sphere if rules.whole_sphere else sphere * np.sign(sphere[:, 2:])  # a BRDF's: the upper hemisphere
        wi = np.roll(wo, 1, axis=0)
        lobes = pb.reference.eval_lobes(material, wi, wo, model=name, energy_compensation=rules.energy_compensation)
        assert {lobe for lobe, value in zip(lobes._fields, lobes) if np.any(value)} == set(rules.lobes), name
        drawn = pb.sample(material, wo.astype(np.float32), seed=3, model=name,
                          energy_compensation=rules.energy_compensation)
        assert {_core.SAMPLED_LOBE_NAMES[k] for k in np.unique(drawn.lobe)} == set(rules.sampled_lobes), name
        below = np.float32([[0.6, 0.0, -0.8]])
        assert (pb.pdf(material, below, np.float32([[0.0, 0.0, 1.0]]), model=name)[0] > 0) == rules.whole_sphere
        if not rules.energy_compensation:
            with pytest.raises(ValueError, match="energy_compensation: not available"):
                pb.eval(material, wi[:1], wo[:1], model=name, energy_compensation=True)
        for unread in rules.unread:
            with pytest.raises(ValueError, match=f"{unread}: model '{name}' does not read it"):
                pb.eval(material.replace(**{unread: 0.25}), wi[:1], wo[:1], model=name)
        if rules.max_specular < np.inf:
            pb.eval(material.replace(specular=rules.max_specular), wi[:1], wo[:1], model=name)
            with pytest.raises(ValueError, match=f"specular: model '{name}' needs specular <="):
                pb.eval(material.replace(specular=rules.max_specular * 1.001), wi[:1], wo[:1], model=name)
        else:
            pb.eval(material.replace(specular=20.0), wi[:1], wo[:1], model=name)
