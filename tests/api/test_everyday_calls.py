"""Everyday calls: fresh or reproducible randomness, many samples of one view."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb

WO = np.float32([0.5, 0.0, 0.8660254])


def test_seed_none_is_fresh_and_an_integer_seed_reproduces():
    m = pb.presets.get("gold")
    a, b = pb.sample(m, WO, n=1000), pb.sample(m, WO, n=1000)
    assert not np.array_equal(a.wi, b.wi)
    c, d = pb.sample(m, WO, n=1000, seed=3), pb.sample(m, WO, n=1000, seed=3)
    np.testing.assert_array_equal(c.wi, d.wi)


def test_n_samples_of_every_element():
    m = pb.Material(roughness=0.3)
    one = pb.sample(m, WO, n=4096, seed=1)
    assert one.wi.shape == (4096, 3) and one.pdf.shape == (4096,)
    np.testing.assert_array_equal(one.wi, pb.sample(m, np.broadcast_to(WO, (4096, 3)), seed=1).wi)
    views = np.float32([[0.0, 0.0, 1.0], WO])
    many = pb.sample(m, views, n=5, seed=2)
    assert many.wi.shape == (5, 2, 3)
    np.testing.assert_array_equal(many.wi, pb.sample(m, np.broadcast_to(views, (5, 2, 3)), seed=2).wi)
    soa = pb.sample(m, WO, n=7, seed=1, layout="soa")
    assert soa.wi.shape == (3, 7)
    with pytest.raises(ValueError, match="n: not with u"):
        pb.sample(m, WO, n=3, u=np.full((3, 3), 0.5))
    with pytest.raises(ValueError, match="n: expected a count >= 0"):
        pb.sample(m, WO, n=-1)
    with pytest.raises(TypeError, match="n: expected an integer"):
        pb.sample(m, WO, n=2.5)


def test_srgb_to_linear_is_the_exact_piecewise_curve():
    c = np.array([0.0, 0.04045, 0.04046, 0.5, 1.0])
    expected = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    np.testing.assert_allclose(pb.srgb_to_linear(c), expected, rtol=1e-15)
    assert pb.srgb_to_linear(1.0) == pytest.approx(1.0, rel=1e-15)
    assert pb.srgb_to_linear(0.5) == pytest.approx(0.21404114048223255, rel=1e-12)
    texture = np.array([[0, 128, 255]], np.uint8)
    np.testing.assert_allclose(pb.srgb_to_linear(texture), pb.srgb_to_linear(texture / 255.0), rtol=1e-15)
    with pytest.raises(ValueError, match=r"color\[0\]: 200.0 is outside its domain \[0, 1\]"):
        pb.srgb_to_linear([200.0, 0.0, 0.0])


def test_linear_to_srgb_is_the_inverse_curve():
    c = np.array([0.0, 0.0031308, 0.0031309, 0.21404114048223255, 1.0])
    expected = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1.0 / 2.4) - 0.055)
    np.testing.assert_allclose(pb.linear_to_srgb(c), expected, rtol=1e-15)
    assert pb.linear_to_srgb(0.21404114048223255) == pytest.approx(0.5, rel=1e-12)
    grid = np.linspace(0.0, 1.0, 1001)
    np.testing.assert_allclose(pb.srgb_to_linear(pb.linear_to_srgb(grid)), grid, rtol=1e-12, atol=1e-15)
    # the 8-bit pictures use the same curve
    linear = np.array([[[0.0, 0.002, 0.5]]])
    np.testing.assert_array_equal(pb.render.to_srgb8(linear, curve="clip"),
                                  np.round(pb.linear_to_srgb(linear) * 255.0).astype(np.uint8))
    with pytest.raises(ValueError, match=r"color\[1\]: 1.5 is outside its domain \[0, 1\]"):
        pb.linear_to_srgb([0.5, 1.5, 0.0])
    with pytest.raises(TypeError, match="color"):
        pb.linear_to_srgb("red")


def test_uint8_and_bright_base_colors_are_not_taken_silently():
    with pytest.raises(TypeError, match="base_color: a uint8 color"):
        pb.Material(base_color=np.array([200, 100, 50], np.uint8))
    with pytest.warns(pb.BrightColorWarning, match=r"base_color: 200 > 1 .*\(a 0-255 or display-encoded color\?\)"):
        bright = pb.Material(base_color=(200.0, 100.0, 50.0))
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pb.Material(base_color=(1.5, 1.0, 1.0), bright_base_color=True)  # asked for: no warning
        bright.replace(roughness=0.2)  # reported once, when it was made
        pb.Material.mix(bright, pb.Material(), 0.5)
        pb.Material(base_color=np.array([1, 0, 0]))  # integers 0 and 1 are fine


def test_material_indexing_slicing_and_reshaping():
    rng = np.random.default_rng(5)
    roughness = rng.uniform(0.1, 0.9, (4, 6))
    color = rng.uniform(0, 1, (4, 6, 3))
    m = pb.Material(roughness=roughness, base_color=color, clearcoat=0.5)
    wi = np.broadcast_to(np.float32([0.3, 0.2, 0.9327379]), (4, 6, 3))
    wo = np.float32([-0.1, 0.4, 0.9110434])
    f = pb.eval(m, wi, wo)
    flat = m.reshape(-1)
    assert flat.shape == (24,) and flat.clearcoat.shape == ()
    np.testing.assert_array_equal(pb.eval(flat, wi.reshape(-1, 3), wo), f.reshape(-1, 3))
    np.testing.assert_array_equal(pb.eval(m[2], wi[2], wo), f[2])
    np.testing.assert_array_equal(pb.eval(m[1:3, ::2], wi[1:3, ::2], wo), f[1:3, ::2])
    mask = roughness > 0.5
    np.testing.assert_array_equal(pb.eval(m[mask], wi[mask], wo), f[mask])
    assert m[3, 4].shape == () and m[3, 4].roughness == roughness[3, 4]
    broadcast = pb.Material(roughness=np.linspace(0.1, 0.9, 6), base_color=np.ones((4, 1, 3)) * 0.5)
    assert broadcast.shape == (4, 6) and broadcast[1].shape == (6,)
    with pytest.raises(IndexError, match="uniform material"):
        pb.Material()[0]
    with pytest.raises(IndexError):
        m[7]
    with pytest.raises(ValueError):
        m.reshape(5)


def test_frames_and_spherical_angles():
    from principled_brdf import frames
    rng = np.random.default_rng(11)
    normals = rng.normal(size=(2000, 3))
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    normals[:3] = [[0, 0, 1], [0, 0, -1], [1, 0, 0]]
    frame = frames.frame_from_normal(normals)
    np.testing.assert_allclose(frame @ np.swapaxes(frame, -1, -2), np.broadcast_to(np.eye(3), frame.shape), atol=1e-14)
    np.testing.assert_allclose(np.cross(frame[:, 0], frame[:, 1]), frame[:, 2], atol=1e-14)  # right-handed
    np.testing.assert_array_equal(frame[:, 2], normals)
    np.testing.assert_allclose(frames.to_local(normals, frame), np.broadcast_to([0.0, 0.0, 1.0], normals.shape),
                               atol=1e-14)
    w = rng.normal(size=(2000, 3))
    np.testing.assert_allclose(frames.to_world(frames.to_local(w, frame), frame), w, atol=1e-13)
    tangent = rng.normal(size=(2000, 3))
    along = frames.frame_from_normal(normals, tangent)
    projected = tangent - np.sum(tangent * normals, axis=-1, keepdims=True) * normals
    np.testing.assert_allclose(along[:, 0], projected / np.linalg.norm(projected, axis=-1, keepdims=True), atol=1e-12)
    with pytest.raises(ValueError, match="tangent: zero or parallel to the normal"):
        frames.frame_from_normal([0.0, 0.0, 1.0], [0.0, 0.0, 2.0])
    theta, phi = rng.uniform(0, np.pi, 500), rng.uniform(-np.pi, np.pi, 500)
    d = frames.spherical_to_direction(theta, phi)
    back_theta, back_phi = frames.direction_to_spherical(d)
    np.testing.assert_allclose(back_theta, theta, atol=1e-12)
    np.testing.assert_allclose(np.cos(back_phi - phi), 1.0, atol=1e-9)
    assert frames.direction_to_spherical([0.0, 0.0, 1.0])[0] == 0.0
    # world-space shading: f of the directions taken into each normal's frame
    m = pb.presets.get("brushed_metal")
    wi_world, wo_world = normals[3:], np.broadcast_to(normals[3:] * 0.8 + [0.0, 0.6, 0.0], normals[3:].shape)
    wo_world = wo_world / np.linalg.norm(wo_world, axis=-1, keepdims=True)
    f = pb.reference.eval(m, frames.to_local(wi_world, frame[3:]), frames.to_local(wo_world, frame[3:]))
    assert np.all(np.isfinite(f)) and np.any(f > 0)


def test_one_signature_for_the_simd_and_reference_calls():
    rng = np.random.default_rng(4)
    wi = rng.normal(size=(50, 3))
    wi[:, 2] = np.abs(wi[:, 2])
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    wo = np.roll(wi, 1, axis=0)
    m = pb.presets.get("car_paint")
    for call in (pb.reference.eval, pb.reference.pdf):
        np.testing.assert_array_equal(call(m, wi.T, wo.T, layout="soa"), np.moveaxis(call(m, wi, wo), -1, 0)
                                      if call is pb.reference.eval else call(m, wi, wo))
    lobes = pb.reference.eval_lobes(m, wi.T, wo.T, layout="soa")
    np.testing.assert_array_equal(lobes.specular, pb.reference.eval_lobes(m, wi, wo).specular.T)
    grad = pb.reference.eval_grad(m, wi.T, wo.T, layout="soa")
    assert grad.jacobian.shape == (3, 13, 50)
    np.testing.assert_array_equal(grad.jacobian, np.moveaxis(pb.reference.eval_grad(m, wi, wo).jacobian, 0, -1))
    u = rng.random((50, 3))
    s_soa, s_aos = pb.reference.sample(m, wo.T, u.T, layout="soa"), pb.reference.sample(m, wo, u)
    np.testing.assert_array_equal(s_soa.wi, s_aos.wi.T)
    np.testing.assert_array_equal(s_soa.pdf, s_aos.pdf)
    wi32, wo32 = wi.astype(np.float32), wo.astype(np.float32)
    np.testing.assert_array_equal(pb.pdf(m, wi32, wo32, model="disney2012"), pb.pdf(m, wi32, wo32))
    with pytest.raises(ValueError, match="model"):
        pb.pdf(m, wi32, wo32, model="disney2099")
    with pytest.raises(ValueError, match="layout: expected 'aos' or 'soa'"):
        pb.reference.eval(m, wi, wo, layout="aosoa")
    with pytest.raises(ValueError, match=r"wi: expected shape \(3, ...\) with layout='soa'"):
        pb.reference.eval(m, wi, wo, layout="soa")


def test_tone_mapping_keeps_hue_and_shading():
    from principled_brdf import render
    rng = np.random.default_rng(8)
    hdr = rng.uniform(0, 1, (200, 3)) * rng.uniform(0, 20, (200, 1))
    for curve, white in (("filmic", render.FILMIC_WHITE), ("reinhard", render.REINHARD_WHITE)):
        display = render.tone_map(hdr, curve=curve)
        assert display.min() >= 0.0 and display.max() <= 1.0
        # hue: the channel ratios survive (no per-channel clipping)
        np.testing.assert_allclose(display / display.sum(-1, keepdims=True), hdr / hdr.sum(-1, keepdims=True),
                                   rtol=1e-12)
        grey = np.linspace(0.0, 0.99 * white, 100)[:, None] * np.ones(3)
        mapped = render.tone_map(grey, curve=curve)[:, 0]
        assert mapped[0] == 0.0 and np.all(np.diff(mapped) > 0)  # bright greys stay distinguishable below white
        assert render.tone_map(np.full(3, white), curve=curve)[0] == pytest.approx(1.0)
        assert render.tone_map(np.full(3, 2 * white), curve=curve)[0] == pytest.approx(1.0, abs=1e-15)
        gold = np.array([8.0, 5.0, 1.0])  # a bright gold highlight stays gold, not white
        g = render.tone_map(gold, curve=curve)
        assert g[0] == pytest.approx(1.0) and g[2] < 0.2
    # the default is the filmic curve, whose midtones stay near the identity (Reinhard's darken)
    np.testing.assert_array_equal(render.tone_map(hdr), render.tone_map(hdr, curve="filmic"))
    assert 0.75 < render.tone_map(np.ones(3))[0] < 0.85 and render.tone_map(np.ones(3), curve="reinhard")[0] < 0.55
    np.testing.assert_array_equal(render.tone_map(hdr, curve="clip"), np.clip(hdr, 0, 1))
    with pytest.raises(ValueError, match="curve: expected one of filmic, reinhard, clip"):
        render.tone_map(hdr, curve="aces")


def test_save_image_by_extension(tmp_path):
    from principled_brdf import render
    import OpenEXR  # a test extra
    hdr = np.random.default_rng(2).uniform(0, 30, (6, 7, 3))
    assert render.save_image(tmp_path / "x.npy", hdr, exposure=0.5) == str(tmp_path / "x.npy")
    np.testing.assert_array_equal(np.load(tmp_path / "x.npy"), (hdr * 0.5).astype(np.float32))
    render.save_image(tmp_path / "x.exr", hdr)
    with OpenEXR.File(str(tmp_path / "x.exr")) as exr:
        np.testing.assert_array_equal(exr.channels()["RGB"].pixels, hdr.astype(np.float32))  # HDR kept
    render.save_image(tmp_path / "x.PNG", hdr)
    import matplotlib.image
    read = matplotlib.image.imread(str(tmp_path / "x.PNG"))[..., :3]
    np.testing.assert_allclose(read * 255, render.to_srgb8(hdr), atol=0.6)
    with pytest.raises(ValueError, match=r"path: cannot write '\.jpg' images; supported: \.png, \.exr, \.npy"):
        render.save_image(tmp_path / "x.jpg", hdr)
    with pytest.raises(ValueError, match=r"linear: expected an \(H, W, 3\) RGB image"):
        render.save_image(tmp_path / "x.png", hdr[..., :2])
