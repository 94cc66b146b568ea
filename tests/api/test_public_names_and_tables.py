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
