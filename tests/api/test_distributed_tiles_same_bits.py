"""principled_brdf.distributed (docs/distributed.md): a texture evaluated or
fitted tile by tile, locally and on a LocalCluster of worker processes, gives
the bits of the single-machine call."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb

da = pytest.importorskip("dask.array")
pbd = pytest.importorskip("principled_brdf.distributed")

H, W = 37, 29  # ragged tiles of 16 x 16


def texture_inputs(seed=3):
    rng = np.random.default_rng(seed)
    wi = rng.normal(size=(H, W, 3))
    wi[..., 2] = np.abs(wi[..., 2])
    wi = (wi / np.linalg.norm(wi, axis=-1, keepdims=True)).astype(np.float32)
    roughness = rng.uniform(0.05, 1.0, (H, W)).astype(np.float32)
    base_color = rng.random((H, W, 3)).astype(np.float32)
    return wi, roughness, base_color


def lazy_eval(wi, roughness, base_color, wo):
    tiles = (16, 16)
    return pbd.eval(pb.Material(metallic=0.5, clearcoat=0.3), da.from_array(wi, chunks=tiles + (3,)), wo,
                    textures={"roughness": da.from_array(roughness, chunks=tiles),
                              "base_color": da.from_array(base_color, chunks=tiles + (3,))}, cosine=True)


def test_a_tiled_texture_evaluates_to_the_same_bits():
    wi, roughness, base_color = texture_inputs()
    wo = np.float32([0.3, 0.1, 0.9486833])
    f = lazy_eval(wi, roughness, base_color, wo)
    assert f.numblocks == (3, 2, 1)
    direct = pb.eval(pb.Material(metallic=0.5, clearcoat=0.3, roughness=roughness, base_color=base_color), wi, wo,
                     cosine=True)
    np.testing.assert_array_equal(pbd.compute(f, progress=False)[0], direct)
    # wo per texel too
    wo_texture = wi[::-1, ::-1].copy()
    f = lazy_eval(wi, roughness, base_color, da.from_array(wo_texture, chunks=(8, 8, 3)))
    direct = pb.eval(pb.Material(metallic=0.5, clearcoat=0.3, roughness=roughness, base_color=base_color), wi,
                     wo_texture, cosine=True)
    np.testing.assert_array_equal(f.compute(), direct)


def test_bad_textures_are_named():
    wi, roughness, _ = texture_inputs()
    with pytest.raises(ValueError, match=r"textures\['roughness'\]: expected shape \(37, 29\)"):
        pbd.eval(pb.Material(), wi, [0, 0, 1.0], textures={"roughness": roughness[:, :3]})
    with pytest.raises(ValueError, match=r"textures: unknown parameter"):
        pbd.eval(pb.Material(), wi, [0, 0, 1.0], textures={"gloss": roughness})
    with pytest.raises(TypeError, match=r"material: expected a principled_brdf.Material"):
        pbd.eval("gold", wi, [0, 0, 1.0])
    with pytest.raises(ValueError, match=r"measured: expected \(H, W, N, 3\)"):
        pbd.fit(wi[0], wi[0], np.zeros((4, 3)))


def fit_inputs():
    rng = np.random.default_rng(9)
    n = 48
    wi = rng.normal(size=(n, 3))
    wi[:, 2] = np.abs(wi[:, 2]) + 0.2
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo = np.roll(wi, 7, axis=0)
    roughness = rng.uniform(0.2, 0.8, (3, 4))
    truth = pb.Material(base_color=(0.8, 0.5, 0.3), metallic=1.0, roughness=roughness[..., None])
    measured = pb.reference.eval(truth, wi, wo)  # (3, 4, n, 3)
    measured[1, 2] = np.nan  # a texel without data
    return wi, wo, measured


def test_a_tiled_fit_is_the_fit_of_each_texel():
    pytest.importorskip("scipy")
    wi, wo, measured = fit_inputs()
    options = {"fit": ["roughness"], "init": {"metallic": 1.0, "base_color": (0.8, 0.5, 0.3)}, "max_iterations": 30}
    result = pbd.fit(wi, wo, da.from_array(measured, chunks=(2, 3, 48, 3)), **options)
    slots, cost, success = pbd.compute(result.slots, result.cost, result.success, progress=False)
    direct = pb.fit(wi, wo, measured.reshape(12, 48, 3), **options)
    np.testing.assert_array_equal(slots.reshape(12, -1), direct.slots)
    np.testing.assert_array_equal(cost.reshape(12), direct.cost)
    np.testing.assert_array_equal(success.reshape(12), direct.success)
    assert not success[1, 2] and success.sum() == 11
    assert result.material().shape == (3, 4)


def test_a_tiled_fit_on_dasks_threads_leaves_the_blas_threads_as_it_found_them():
    """The default (batched) fit takes no BLAS call that needs limiting: run on dask's threaded
    scheduler, it leaves every BLAS library's thread count as it was."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    dask = pytest.importorskip("dask")
    wi, wo, measured = fit_inputs()

    def blas_threads():
        return [info["num_threads"] for info in threadpoolctl.threadpool_info() if info["user_api"] == "blas"]

    before = blas_threads()
    with dask.config.set(scheduler="threads"):
        result = pbd.fit(wi, wo, da.from_array(measured, chunks=(1, 2, 48, 3)), fit=["roughness"],
                         init={"metallic": 1.0, "base_color": (0.8, 0.5, 0.3)})
        pbd.compute(result.slots, progress=False)
    assert blas_threads() == before


def test_a_cluster_of_worker_processes_gives_the_same_bits():
    distributed = pytest.importorskip("distributed")
    pytest.importorskip("scipy")
    wi, roughness, base_color = texture_inputs(4)
    wo = np.float32([0.0, 0.6, 0.8])
    direct = pb.eval(pb.Material(metallic=0.5, clearcoat=0.3, roughness=roughness, base_color=base_color), wi, wo,
                     cosine=True)
    fit_wi, fit_wo, measured = fit_inputs()
    options = {"fit": ["roughness"], "init": {"metallic": 1.0, "base_color": (0.8, 0.5, 0.3)}, "max_iterations": 30}
    direct_fit = pb.fit(fit_wi, fit_wo, measured.reshape(12, 48, 3), **options)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster):
        f = lazy_eval(wi, roughness, base_color, wo)
        fitted = pbd.fit(fit_wi, fit_wo, da.from_array(measured, chunks=(2, 2, 48, 3)), **options)
        values, slots = pbd.compute(f, fitted.slots)
    np.testing.assert_array_equal(values, direct)
    np.testing.assert_array_equal(slots.reshape(12, -1), direct_fit.slots)
