"""Evaluate the principled BRDF on arrays larger than memory with dask.

``pb.eval`` works on numpy arrays that fit in RAM. To go further, hold the
directions (and any per-element parameters) as dask arrays chunked along the
element axis N and evaluate each chunk with ``pb.eval``::

    import dask.array as da
    import principled_brdf as pb
    from dask_scale_out import eval_dask

    wi = ...                                          # dask (N, 3) float32, chunks (c, 3)
    wo = ...                                          # dask (N, 3), or one numpy (3,) view direction
    roughness = ...                                   # dask (N,), any chunks (rechunked to wi's)
    f = eval_dask(pb.presets.get("gold"), wi, wo, per_element={"roughness": roughness})
    f.mean(axis=0).compute()                          # or f.to_zarr(...), da.store(f, h5_dataset), ...

``eval_dask`` builds a lazy graph with ``dask.array.map_blocks``: one task per
chunk, each calling ``pb.eval`` on the chunk's numpy arrays. Nothing is read
until a result is asked for, and a reduction (``mean``, ``sum``, a histogram)
or a store (``to_zarr``) streams through the chunks, so the whole array never
sits in memory: each worker thread holds a few chunks at a time.
The kernel evaluates each element on its own, so a chunked evaluation gives
the same bits as one ``pb.eval`` on the materialised arrays (the tests check
this, ragged last chunk included).

Uniform parameters come from ``material`` (a uniform ``pb.Material``); they
travel into each task as plain numbers. Per-element parameters are dask arrays
in ``per_element``: ``(N,)`` for scalars, ``(N, 3)`` for ``base_color``.

On a cluster
------------
The same code runs on a ``dask.distributed`` cluster; only the scheduler
changes::

    from dask.distributed import Client
    client = Client("tcp://scheduler-address:8786")   # or LocalCluster(), SLURMCluster(), ...
    wi = da.from_zarr("s3://bucket/wi.zarr")          # data each worker can read
    f = eval_dask(material, wi, wo, per_element={"roughness": da.from_zarr("s3://bucket/r.zarr")})
    f.to_zarr("s3://bucket/f.zarr")                   # or f.mean(axis=0).compute()

With a ``Client`` created, ``compute``/``to_zarr`` use it automatically. What
a cluster needs:

* ``principled_brdf`` installed on every worker (same version, built for each
  worker's CPU: the instruction set is picked at import time on the worker, so
  mixed AVX2 / AVX-512 nodes are fine and give the same results within the
  accuracy bounds of docs/validation.md);
* inputs the workers can read themselves (zarr/HDF5 on shared or object
  storage, or dask arrays generated on the workers); avoid ``da.from_array``
  of a large local numpy array, which ships it through the client;
* tasks carry only the block function, plain numbers and numpy chunks: the
  material travels as a dict of its uniform parameters (a ``pb.Material``
  pickles too, but plain numbers keep the task graph small), so everything
  serialises with the standard pickle (``f.compute(scheduler="processes")``
  is a quick local check: the tasks are pickled to worker processes, as a
  cluster does);
* ``threads``: the number of kernel threads per task. Dask already runs one
  task per worker thread, so the default ``threads=1`` avoids oversubscription;
  with ``dask worker --nthreads 1`` pass ``threads=None`` (all cores of the
  worker per task). Results are bit-identical for every choice.

Chunks of 2^18 to 2^22 elements (3 MB to 50 MB of float32 directions) keep the
per-task overhead (~1 ms) small against the kernel time and the memory per
task modest.

Run ``python examples/dask_scale_out.py`` for a demo (``--help`` for options).
"""

from __future__ import annotations

import argparse
import time

import dask
import dask.array as da
import numpy as np

import principled_brdf as pb

__all__ = ["eval_dask", "random_directions", "main"]

_RGB_PARAMETERS = ("base_color",)


def _eval_block(wi, wo, *per_element_blocks, names, uniform, model, cosine, threads, check):
    """One chunk: numpy blocks in, ``pb.eval`` out. Module level, so tasks pickle by reference."""
    params = dict(uniform)
    for name, block in zip(names, per_element_blocks):
        # scalar parameters travel as (c, 1) blocks so that they align with the (c, 3) directions
        params[name] = block if name in _RGB_PARAMETERS else block[:, 0]
    material = pb.Material(**params)
    return pb.eval(material, wi, wo, model=model, cosine=cosine, threads=threads, check=check)


def eval_dask(material: pb.Material, wi, wo, *, per_element: dict | None = None, model: str = "disney2014",
              cosine: bool = False, threads: int | None = 1, check: bool = True) -> da.Array:
    """Lazy ``pb.eval`` over dask arrays: a float32 dask array ``(N, 3)`` chunked like ``wi``.

    material
        A uniform ``pb.Material``; its parameters apply to every element unless
        overridden in ``per_element``.
    wi
        Dask (or numpy) array ``(N, 3)`` of unit directions towards the light,
        chunked along N only (``chunks=(c, 3)``); its chunks set the tasks.
    wo
        Dask array ``(N, 3)`` (rechunked to ``wi``'s chunks if needed) or one
        direction ``(3,)`` shared by every element.
    per_element
        ``{name: array}`` of per-element parameters, dask or numpy, ``(N,)``
        (``(N, 3)`` for ``base_color``), rechunked to ``wi``'s chunks.
    model, cosine, check
        As in ``pb.eval``.
    threads
        Kernel threads per task (default 1: dask runs the tasks in parallel).
    """
    if not isinstance(material, pb.Material):
        raise TypeError(f"material: expected a principled_brdf.Material, got {type(material).__name__}")
    if not material.is_uniform:
        raise ValueError("material: expected uniform parameters; pass per-element ones in per_element")
    wi = da.asarray(wi)
    if wi.ndim != 2 or wi.shape[1] != 3:
        raise ValueError(f"wi: expected shape (N, 3), got {wi.shape}")
    wi = wi.rechunk({1: 3})  # one chunk across the three components
    n, row_chunks = wi.shape[0], wi.chunks[0]

    def aligned(name, value, rgb):
        array = da.asarray(value)
        expected = (n, 3) if rgb else (n,)
        if array.shape != expected:
            raise ValueError(f"{name}: expected shape {expected}, got {array.shape}")
        if not rgb:
            array = array[:, None]  # (N, 1): map_blocks aligns trailing axes
        return array.rechunk((row_chunks, array.shape[1]))

    uniform = {name: (tuple(float(c) for c in value) if name in _RGB_PARAMETERS else float(value))
               for name, value in material.as_dict().items()}
    per_element = dict(per_element or {})
    unknown = set(per_element) - set(uniform)
    if unknown:
        raise TypeError(f"per_element: unknown parameter(s) {', '.join(sorted(unknown))}")
    names = tuple(sorted(per_element))
    blocks = [aligned(name, per_element[name], name in _RGB_PARAMETERS) for name in names]
    for name in names:
        uniform.pop(name)

    if isinstance(wo, da.Array) or np.ndim(wo) == 2:
        wo_arg = aligned("wo", wo, rgb=True)
    else:
        wo_arg = np.asarray(wo, dtype=np.float32)
        if wo_arg.shape != (3,):
            raise ValueError(f"wo: expected shape (N, 3) or (3,), got {wo_arg.shape}")
        # a numpy constant: map_blocks passes it unchanged to every task
    return da.map_blocks(
        _eval_block, wi, wo_arg, *blocks,
        names=names, uniform=uniform, model=model, cosine=cosine, threads=threads, check=check,
        dtype=np.float32, chunks=wi.chunks, meta=np.empty((0, 3), np.float32),
    )


def random_directions(n: int, chunk: int, seed: int) -> da.Array:
    """Lazy ``(n, 3)`` float32 unit vectors, uniform over the upper hemisphere (cos θ uniform in [0, 1))."""
    u = da.random.default_rng(seed).random(size=(n, 2), chunks=(chunk, 2))
    cos_theta, phi = u[:, 0], 2.0 * np.pi * u[:, 1]
    sin_theta = da.sqrt(1.0 - cos_theta * cos_theta)
    return da.stack([sin_theta * da.cos(phi), sin_theta * da.sin(phi), cos_theta], axis=1).astype(np.float32)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description="pb.eval over chunked dask arrays")
    parser.add_argument("--n", type=int, default=4_000_000, help="number of direction pairs")
    parser.add_argument("--chunk", type=int, default=1 << 20, help="elements per chunk")
    args = parser.parse_args(argv)

    n, chunk = args.n, args.chunk
    wi = random_directions(n, chunk, seed=1)
    wo = random_directions(n, chunk, seed=2)
    rng = da.random.default_rng(3)
    roughness = rng.uniform(0.05, 1.0, size=n, chunks=chunk).astype(np.float32)  # a "roughness texture"
    material = pb.presets.get("car_paint")
    f = eval_dask(material, wi, wo, per_element={"roughness": roughness}, cosine=True)
    print(f"pb {pb.__version__}, {pb.cpu_info()['isa']}; dask {dask.__version__}")
    print(f"f: {f.shape} {f.dtype}, {f.numblocks[0]} chunks of up to {chunk} elements, "
          f"{f.nbytes / 1e6:.0f} MB if materialised")

    # A reduction streams through the chunks: the (N, 3) result never exists as a whole,
    # and here the random inputs are generated chunk by chunk inside the same tasks.
    start = time.perf_counter()
    mean, peak = dask.compute(f.mean(axis=0), f.max())
    seconds = time.perf_counter() - start
    print(f"mean f cos θl = {np.array2string(mean, precision=5)}, max = {peak:.4g}")
    print(f"inputs generated on the fly: {n / seconds / 1e6:6.1f} M pairs/s ({seconds:.2f} s)")

    # The same with the inputs already in (distributed) memory: the kernel's share.
    wi, wo, roughness = dask.persist(wi, wo, roughness)
    f = eval_dask(material, wi, wo, per_element={"roughness": roughness}, cosine=True)
    start = time.perf_counter()
    dask.compute(f.mean(axis=0), f.max())
    seconds = time.perf_counter() - start
    print(f"inputs persisted:             {n / seconds / 1e6:6.1f} M pairs/s ({seconds:.2f} s)")

    # One chunk against a direct pb.eval call on the same numpy data: the same bits.
    wi0, wo0, r0, f0 = dask.compute(wi.blocks[0], wo.blocks[0], roughness.blocks[0], f.blocks[0])
    direct = pb.eval(material.replace(roughness=r0), wi0, wo0, cosine=True)
    same = np.array_equal(direct.view(np.uint32), f0.view(np.uint32))
    print(f"first chunk identical to pb.eval on the materialised arrays: {same}")
    if not same:
        raise SystemExit("chunked evaluation differs from pb.eval")


if __name__ == "__main__":
    main()
