"""Broadcast arguments are read in place (docs/evaluating.md): a grid of views
against a texture gives the bits of the call on materialised copies, and no
full-size copy of an argument is made."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import principled_brdf as pb

ISAS = pb.cpu_info()["available"]


def unit(rng, shape):
    v = rng.normal(size=shape + (3,))
    v[..., 2] = np.abs(v[..., 2])
    return (v / np.linalg.norm(v, axis=-1, keepdims=True)).astype(np.float32)


def texture(rng, shape):
    return pb.Material(roughness=rng.uniform(0.05, 1, shape), base_color=rng.random(shape + (3,)), sheen=0.5,
                       clearcoat=rng.random(shape))


CASES = {  # name: (wi shape, wo shape, material shape)
    "views against a texture": ((4, 3, 1, 1), (4, 3, 1, 1), (40, 50)),
    "one view, a light per texel": ((40, 50), (), (40, 50)),
    "a light grid against a texture": ((6, 1, 1), (), (40, 50)),
    "broadcast view rows": ((5, 40, 50), (5, 1, 1), (40, 50)),
}


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("case", sorted(CASES))
def test_broadcast_calls_give_the_bits_of_materialised_ones(isa, case):
    wi_shape, wo_shape, material_shape = CASES[case]
    rng = np.random.default_rng(len(case))
    wi, wo, material = unit(rng, wi_shape), unit(rng, wo_shape), texture(rng, material_shape)
    leading = np.broadcast_shapes(wi_shape, wo_shape, material_shape)
    full = pb.Material(**{name: np.broadcast_to(getattr(material, name), leading + np.shape(getattr(material, name))[
        len(material_shape):]) for name in pb.PARAMETERS})
    wi_full = np.ascontiguousarray(np.broadcast_to(wi, leading + (3,)))
    wo_full = np.ascontiguousarray(np.broadcast_to(wo, leading + (3,)))
    np.testing.assert_array_equal(pb.eval(material, wi, wo, isa=isa), pb.eval(full, wi_full, wo_full, isa=isa))
    for a, b in zip(pb.eval_lobes(material, wi, wo, isa=isa), pb.eval_lobes(full, wi_full, wo_full, isa=isa)):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(pb.pdf(material, wi, wo, isa=isa), pb.pdf(full, wi_full, wo_full, isa=isa))
    g, g_full = pb.eval_grad(material, wi, wo, isa=isa), pb.eval_grad(full, wi_full, wo_full, isa=isa)
    np.testing.assert_array_equal(g.jacobian, g_full.jacobian)
    np.testing.assert_array_equal(pb.eval_pdf(material, wi, wo, isa=isa)[1],
                                  pb.eval_pdf(full, wi_full, wo_full, isa=isa)[1])


def test_a_grid_of_views_against_a_texture_makes_no_full_size_copy():
    rng = np.random.default_rng(7)
    views = unit(rng, (8, 8, 1, 1))
    material = texture(rng, (128, 128))
    pb.eval(material, views, [0.0, 0.0, 1.0])  # the material's float32 arrays, cached on it
    tracemalloc.start()
    f = pb.eval(material, views, [0.0, 0.0, 1.0])
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert f.shape == (8, 8, 128, 128, 3)
    assert peak < 1.1 * f.nbytes, f"peak {peak / 1e6:.1f} MB for a {f.nbytes / 1e6:.1f} MB result"


def test_a_bad_direction_in_a_segment_is_named_in_its_own_shape():
    rng = np.random.default_rng(8)
    views = unit(rng, (3, 2, 1, 1))
    views[2, 1, 0, 0] = [0.0, 0.0, 1.5]
    with pytest.raises(ValueError, match=r"wi\[2, 1, 0, 0\]: length 1.5"):
        pb.eval(texture(rng, (40, 40)), views, [0.0, 0.0, 1.0])
