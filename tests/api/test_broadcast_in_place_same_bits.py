"""Broadcast arguments are read in place (docs/evaluating.md): a grid of views
against a texture gives the bits of the call on materialised copies, in both
layouts and for every entry point, and no full-size copy of an argument is made."""

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
    "materials against a direction table": ((40, 50), (40, 50), (3, 2, 1, 1)),
    "a texture column against view rows": ((6, 1, 50), (), (40, 1)),
}


def materialised(material, leading):
    return pb.Material(**{name: np.ascontiguousarray(np.broadcast_to(
        getattr(material, name), leading + np.shape(getattr(material, name))[len(material.shape):]))
        for name in pb.PARAMETERS})


def soa(v):
    return np.ascontiguousarray(np.moveaxis(v, -1, 0))


@pytest.mark.parametrize("case", sorted(CASES))
def test_every_entry_point_in_both_layouts_gives_the_bits_of_materialised_arguments(case):
    wi_shape, wo_shape, material_shape = CASES[case]
    rng = np.random.default_rng(len(case) + 100)
    wi, wo, material = unit(rng, wi_shape), unit(rng, wo_shape), texture(rng, material_shape)
    leading = np.broadcast_shapes(wi_shape, wo_shape, material_shape)
    full = materialised(material, leading)
    wi_full = np.ascontiguousarray(np.broadcast_to(wi, leading + (3,)))
    wo_full = np.ascontiguousarray(np.broadcast_to(wo, leading + (3,)))
    g = rng.normal(size=(1,) * (len(leading) - 1) + leading[-1:] + (3,)).astype(np.float32)
    for layout, convert in (("aos", lambda v: v), ("soa", soa)):
        a, b = (convert(wi), convert(wo)), (convert(wi_full), convert(wo_full))
        for threads in (1, 2):
            options = dict(layout=layout, threads=threads)
            np.testing.assert_array_equal(pb.eval(material, *a, **options), pb.eval(full, *b, **options))
            np.testing.assert_array_equal(pb.eval_pdf(material, *a, **options, energy_compensation=True)[1],
                                          pb.eval_pdf(full, *b, **options, energy_compensation=True)[1])
        np.testing.assert_array_equal(pb.eval_grad(material, *a, layout=layout).jacobian,
                                      pb.eval_grad(full, *b, layout=layout).jacobian)
        # the products per element (a full-shape roughness), the cotangent a broadcast row
        g_full = convert(np.ascontiguousarray(np.broadcast_to(g, leading + (3,))))
        np.testing.assert_array_equal(pb.eval_vjp(full, *a, convert(g), layout=layout, wrt="roughness")["roughness"],
                                      pb.eval_vjp(full, *b, g_full, layout=layout, wrt="roughness")["roughness"])


@pytest.mark.parametrize("layout", ["aos", "soa"])
def test_sampling_broadcast_arguments_gives_the_bits_of_materialised_ones(layout):
    rng = np.random.default_rng(11)
    material = texture(rng, (40, 50))
    wo = unit(rng, (3, 1, 1))
    u = rng.random((3, 1, 50, 3)).astype(np.float32)
    leading = (3, 40, 50)
    full = materialised(material, leading)
    wo_full = np.ascontiguousarray(np.broadcast_to(wo, leading + (3,)))
    u_full = np.ascontiguousarray(np.broadcast_to(u, leading + (3,)))
    convert = (lambda v: v) if layout == "aos" else soa
    for arguments in (dict(seed=5), dict(u=convert(u)), dict(seed=6, n=2)):
        full_arguments = dict(arguments, u=convert(u_full)) if "u" in arguments else arguments
        ours = pb.sample(material, convert(wo), layout=layout, **arguments)
        theirs = pb.sample(full, convert(wo_full), layout=layout, **full_arguments)
        for a, b in zip(ours, theirs):
            np.testing.assert_array_equal(a, b)


def test_a_material_of_broadcast_views_keeps_them_unexpanded_and_gives_the_same_bits():
    rng = np.random.default_rng(12)
    roughness = rng.uniform(0.05, 1, (64, 64))
    material = pb.Material(roughness=np.broadcast_to(roughness, (16, 64, 64)), base_color=(0.5, 0.4, 0.3))
    assert material.roughness.shape == (16, 64, 64) and material.roughness.strides[0] == 0
    wi = unit(rng, (16, 1, 1))
    full = pb.Material(roughness=np.ascontiguousarray(material.roughness), base_color=(0.5, 0.4, 0.3))
    np.testing.assert_array_equal(pb.eval(material, wi, [0.0, 0.0, 1.0]), pb.eval(full, wi, [0.0, 0.0, 1.0]))


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


@pytest.mark.parametrize("layout", ["aos", "soa"])
def test_a_grid_of_views_against_a_texture_makes_no_full_size_copy(layout):
    rng = np.random.default_rng(7)
    views = unit(rng, (8, 8, 1, 1))
    views = views if layout == "aos" else soa(views)
    material = texture(rng, (128, 128))
    pb.eval(material, views, [0.0, 0.0, 1.0], layout=layout)  # the material's float32 arrays, cached on it
    tracemalloc.start()
    f = pb.eval(material, views, [0.0, 0.0, 1.0], layout=layout)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert f.size == 8 * 8 * 128 * 128 * 3
    assert peak < 1.1 * f.nbytes, f"peak {peak / 1e6:.1f} MB for a {f.nbytes / 1e6:.1f} MB result"


def test_a_material_of_broadcast_views_is_neither_stored_nor_read_expanded():
    rng = np.random.default_rng(9)
    leading = (8, 8, 128, 128)
    roughness = np.broadcast_to(rng.uniform(0.05, 1, (128, 128)), leading)  # 8 MB expanded as float64
    views = np.broadcast_to(unit(rng, (8, 8, 1, 1)), leading + (3,))
    tracemalloc.start()
    material = pb.Material(roughness=roughness)
    f = pb.eval(material, views, [0.0, 0.0, 1.0])
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert material.shape == leading
    assert peak < 1.1 * f.nbytes, f"peak {peak / 1e6:.1f} MB for a {f.nbytes / 1e6:.1f} MB result"


@pytest.mark.parametrize("layout", ["aos", "soa"])
def test_a_bad_direction_in_a_segment_is_named_in_its_own_shape(layout):
    rng = np.random.default_rng(8)
    views = unit(rng, (3, 2, 1, 1))
    views[2, 1, 0, 0] = [0.0, 0.0, 1.5]
    light = np.broadcast_to(np.float32([0.0, 0.0, 1.0]), (40, 40, 3))  # a stride-0 view
    convert = (lambda v: v) if layout == "aos" else (lambda v: np.moveaxis(v, -1, 0))
    with pytest.raises(ValueError, match=r"wi\[2, 1, 0, 0\]: length 1.5"):
        pb.eval(texture(rng, (40, 40)), convert(views), convert(light), layout=layout)
