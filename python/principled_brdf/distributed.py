"""Evaluation and fitting of textures beyond one machine, with dask (docs/distributed.md).

Textures are dask arrays chunked by tiles of texels: a per-texel parameter is
``(H, W)`` (``base_color`` ``(H, W, 3)``), directions ``(H, W, 3)`` or one shared
``(3,)``, measurements ``(H, W, N, 3)``. Each tile is one task that calls the
library on its numpy blocks, so a result has the same bits as the call on the
materialised arrays, and the same code runs on a ``dask.distributed`` cluster:
with a ``Client`` created, ``compute`` uses it. Every worker needs
``principled_brdf`` (and, to fit, scipy) installed; the tasks carry plain
numbers and numpy blocks and pickle by reference to this module.

    import dask.array as da
    from principled_brdf import distributed as pbd
    f = pbd.eval(pb.Material(metallic=1), wi, wo, textures={"roughness": r})   # lazy (H, W, 3)
    pbd.compute(f.mean(axis=(0, 1)))                                          # with a progress bar
"""

from __future__ import annotations

import importlib
import re
import typing

from collections.abc import Mapping as _Mapping

import numpy as np

from . import _gradient, _validate
from ._batch import eval as _eval
from .material import PARAMETERS, Material

if typing.TYPE_CHECKING:
    from typing import Any

    import dask.array as da

    from ._typing import Model

__all__ = ["eval", "fit", "TextureFit", "compute"]


def _dask() -> Any:
    try:
        import dask.array
    except ImportError as error:  # pragma: no cover - dask is in the test and distributed extras
        raise ImportError("principled_brdf.distributed needs dask: pip install 'principled-brdf[distributed]'") \
            from error
    return dask.array


def _texture(name: str, value: object, leading: tuple[int, ...], chunks: tuple[tuple[int, ...], ...],
             trailing: tuple[int, ...]) -> da.Array:
    """``value`` as a dask array of shape ``leading + trailing``, tiled like ``chunks`` (the
    trailing axes whole)."""
    array = _dask().asarray(value)
    if array.shape != leading + trailing:
        raise ValueError(f"{name}: expected shape {leading + trailing}, got {array.shape}")
    return array.rechunk(chunks + tuple((size,) for size in trailing))


# An error message naming an element: "name[i, j, ...]: ..." (docs/bad-input.md)
_ELEMENT = re.compile(r"^(\w+)\[(\d+(?:, \d+)*)\](.*)$", re.DOTALL)


def _tile_start(block_info: dict[Any, Any] | None, axes: int) -> tuple[int, ...]:
    """The index in the whole texture of a tile's first texel (map_blocks' block_info)."""
    if block_info is None:  # (called outside map_blocks)
        return (0,) * axes
    return tuple(int(begin) for begin, _ in block_info[None]["array-location"][:axes])


def _in_texture(error: Exception, tile_start: tuple[int, ...], tile_shape: tuple[int, ...],
                per_texel: tuple[str, ...], flattened: bool) -> Exception:
    """``error`` with the element of a tile's block it names (``name[i, j, ...]``, for a name
    in ``per_texel``) named by its index in the whole texture: the tile's start plus the
    texel's index in the tile (its first axes, or with ``flattened`` its first index, which
    counts the tile's texels in order, as a fit's batch of problems); any other error as it is."""
    match = _ELEMENT.match(str(error))
    if match is None or match.group(1) not in per_texel:
        return error
    index = [int(i) for i in match.group(2).split(", ")]
    if flattened:
        index = [int(i) for i in np.unravel_index(index[0], tile_shape)] + index[1:]
    texel = [begin + i for begin, i in zip(tile_start, index)] + index[len(tile_start):]
    return type(error)(f"{match.group(1)}[{', '.join(str(i) for i in texel)}]{match.group(3)}")


def _eval_tile(wi: np.ndarray, wo: np.ndarray, *blocks: np.ndarray, names: tuple[str, ...],
               uniform: dict[str, Any], model: str, cosine: bool, threads: int | None, check: bool,
               block_info: dict[Any, Any] | None = None) -> np.ndarray:
    """One tile: numpy blocks in, pb.eval out (module level, so that tasks pickle by reference);
    an error names a bad texel by its index in the whole texture."""
    params = dict(uniform)
    for name, block in zip(names, blocks):
        params[name] = block if PARAMETERS[name].slots == 3 else block[..., 0]
    try:
        return _eval(Material(**params), wi, wo, model=typing.cast("Model", model), cosine=cosine, threads=threads,
                     check=check)
    except (ValueError, TypeError) as error:
        tile = wi.shape[:-1]
        per_texel = names + ("wi",) + (("wo",) if wo.ndim > 1 else ())
        renamed = _in_texture(error, _tile_start(block_info, len(tile)), tile, per_texel, flattened=False)
        if renamed is error:
            raise
        raise renamed from error


def eval(material: Material, wi: object, wo: object, *, textures: dict[str, object] | None = None,
         model: Model = "disney2014", cosine: bool = False, threads: int | None = 1, check: bool = True) -> da.Array:
    """Lazy :func:`principled_brdf.eval` of a texture: float32 ``(H, W, 3)`` tiled like ``wi``.

    ``material``: a uniform Material, its parameters the texture's wherever
    ``textures`` does not give one per texel. ``wi``: a dask (or numpy) array
    ``(H, W, 3)`` of unit directions chunked by tiles of texels (the last axis
    whole); its chunks are the tasks. ``wo``: the same shape (rechunked to
    ``wi``'s tiles) or one direction ``(3,)``. ``textures``: ``{name: array}``,
    ``(H, W)`` per parameter (``(H, W, 3)`` for ``base_color``). ``threads``:
    kernel threads per task (default 1: dask runs the tasks in parallel).
    Any number of leading axes works as ``(H, W)`` does.
    """
    dask_array = _dask()
    if not isinstance(material, Material):
        raise TypeError(f"material: expected a principled_brdf.Material, got {type(material).__name__}")
    if not material.is_uniform:
        raise ValueError("material: expected uniform parameters; give per-texel ones in textures")
    _validate.model_index(model)
    if textures is not None and not isinstance(textures, _Mapping):
        raise TypeError(f"textures: expected a mapping {{name: array}}, got {type(textures).__name__}")
    wi_array = dask_array.asarray(wi)
    if wi_array.ndim < 2 or wi_array.shape[-1] != 3:
        raise ValueError(f"wi: expected a texture of directions (H, W, 3), got shape {wi_array.shape}")
    leading = wi_array.shape[:-1]
    wi_array = wi_array.rechunk(wi_array.chunks[:-1] + ((3,),))
    tiles = wi_array.chunks[:-1]
    per_texel = dict(textures or {})
    unknown = sorted(set(per_texel) - set(PARAMETERS))
    if unknown:
        raise ValueError(f"textures: unknown parameter(s) {', '.join(unknown)}; expected names of pb.PARAMETERS")
    names = tuple(sorted(per_texel))
    blocks = []
    for name in names:
        value = dask_array.asarray(per_texel[name])
        if PARAMETERS[name].slots == 1:
            if value.shape != leading:
                raise ValueError(f"textures[{name!r}]: expected shape {leading}, got {value.shape}")
            value = value[..., None]  # (H, W, 1): map_blocks aligns trailing axes with the directions'
        blocks.append(_texture(f"textures[{name!r}]", value, leading, tiles, (PARAMETERS[name].slots,)))
    uniform: dict[str, Any] = {
        name: tuple(float(c) for c in np.ravel(value)) if PARAMETERS[name].slots == 3 else float(value)
        for name, value in material.as_dict().items() if name not in per_texel}
    if np.shape(typing.cast("Any", wo)) == (3,) and not isinstance(wo, dask_array.Array):
        wo_argument: object = np.asarray(_validate.directions("wo", wo), dtype=np.float32)
    else:
        wo_argument = _texture("wo", wo, leading, tiles, (3,))
    return dask_array.map_blocks(_eval_tile, wi_array, wo_argument, *blocks, names=names, uniform=uniform,
                                 model=model, cosine=_validate.flag("cosine", cosine), threads=threads,
                                 check=_validate.flag("check", check), dtype=np.float32, chunks=wi_array.chunks,
                                 meta=np.empty((0,) * len(leading) + (3,), np.float32))


class TextureFit(typing.NamedTuple):
    """What :func:`fit` returns: lazy dask arrays over the texture's ``(H, W)``."""

    slots: da.Array  # (H, W, P) float64: the fitted values in the model's derivative slots (pb.fit's slots)
    cost: da.Array  # (H, W) float64
    success: da.Array  # (H, W) bool

    def material(self) -> Material:
        """The fitted texture as a per-texel Material (computes the slots)."""
        slots = np.asarray(compute(self.slots, progress=False)[0])
        values = {name: slots[..., info.first_slot:info.first_slot + info.slots] if info.slots == 3
                  else slots[..., info.first_slot] for name, info in PARAMETERS.items()
                  if info.first_slot < slots.shape[-1]}
        return Material(**values, bright_base_color=True)


def _fit_tile(measured: np.ndarray, wi: np.ndarray, wo: np.ndarray, *, options: dict[str, Any],
              block_info: dict[Any, Any] | None = None) -> np.ndarray:
    """One tile of texels: pb.fit of its (B, N, 3) problems; the slots, the cost and success
    packed as (th, tw, P + 2) float64 (module level, so that tasks pickle by reference); an
    error names a bad texel by its index in the whole texture."""
    from .fitting import fit as _fit

    tile = measured.shape[:-2]
    problems = measured.reshape((-1,) + measured.shape[-2:])
    directions = [w if w.ndim == 2 else w.reshape(problems.shape) for w in (wi, wo)]
    try:
        result = _fit(directions[0], directions[1], problems, **options)
    except (ValueError, TypeError) as error:
        per_texel = ("measured",) + tuple(name for name, w in (("wi", wi), ("wo", wo)) if w.ndim > 2)
        renamed = _in_texture(error, _tile_start(block_info, len(tile)), tile, per_texel, flattened=True)
        if renamed is error:
            raise
        raise renamed from error
    packed = np.concatenate([np.atleast_2d(result.slots), np.atleast_1d(result.cost)[:, None],
                             np.atleast_1d(result.success)[:, None].astype(np.float64)], axis=1)
    return packed.reshape(tile + (packed.shape[-1],))


def fit(wi: object, wo: object, measured: object, **options: Any) -> TextureFit:
    """Lazy :func:`principled_brdf.fit` of a texture of measurements, one task per tile.

    ``measured``: a dask (or numpy) array ``(H, W, N, 3)`` of f in 1/sr (NaN for a
    missing sample), chunked by tiles of texels (N and the channels whole).
    ``wi``, ``wo``: the pairs, ``(N, 3)`` shared by every texel (numpy) or
    ``(H, W, N, 3)`` per texel. ``options``: those of :func:`principled_brdf.fit`
    (``init``, ``fit``, ``loss``, ``weights`` of shape ``(N,)``, ``bounds``,
    ``model``, ...), the same for every texel. Each texel's result is the one
    ``pb.fit`` gives it on one machine.
    """
    dask_array = _dask()
    measured_array = dask_array.asarray(measured)
    if measured_array.ndim < 3 or measured_array.shape[-1] != 3:
        raise ValueError(f"measured: expected (H, W, N, 3) values of f, got shape {measured_array.shape}")
    leading, n = measured_array.shape[:-2], measured_array.shape[-2]
    measured_array = measured_array.rechunk(measured_array.chunks[:-2] + ((n,), (3,)))
    tiles = measured_array.chunks[:-2]
    pair_arguments: list[Any] = []
    for name, value in (("wi", wi), ("wo", wo)):
        if isinstance(value, dask_array.Array) or np.ndim(typing.cast("Any", value)) > 2:
            pair_arguments.append(_texture(name, value, leading, tiles, (n, 3)))
        else:
            directions = np.asarray(_validate.directions(name, value), dtype=np.float64)
            if directions.shape != (n, 3):
                raise ValueError(f"{name}: expected the pairs (N, 3) with N = {n}, or (H, W, N, 3), "
                                 f"got {directions.shape}")
            pair_arguments.append(directions)
    if "weights" in options and options["weights"] is not None and np.shape(options["weights"]) != (n,):
        raise ValueError(f"weights: expected one weight per pair, shape ({n},), got {np.shape(options['weights'])}")
    model = options.get("model", "disney2014")
    _validate.model_index(model)
    slots = len(_gradient.gradient_names(model))  # pb.fit's slots for the model
    packed = dask_array.map_blocks(_fit_tile, measured_array, *pair_arguments, options=options,
                                   dtype=np.float64, chunks=tiles + ((slots + 2,),),
                                   drop_axis=[len(leading) + 1], meta=np.empty((0,) * len(leading) + (0,)))
    return TextureFit(packed[..., :slots], packed[..., slots], packed[..., slots + 1] > 0.5)


def compute(*arrays: Any, progress: bool = True) -> tuple[Any, ...]:
    """``dask.compute(*arrays)`` with a progress bar: ``distributed``'s when a
    ``Client`` is active (the work runs on its cluster), dask's local one otherwise."""
    dask: Any = importlib.import_module("dask")
    client = None
    try:
        distributed: Any = importlib.import_module("distributed")
        client = distributed.default_client()
    except (ImportError, ValueError):
        pass
    if client is not None:
        futures = client.compute(list(arrays))
        if progress:
            distributed.progress(futures)
        return tuple(client.gather(futures))
    if progress:
        diagnostics: Any = importlib.import_module("dask.diagnostics")
        with diagnostics.ProgressBar():
            return tuple(dask.compute(*arrays))
    return tuple(dask.compute(*arrays))
