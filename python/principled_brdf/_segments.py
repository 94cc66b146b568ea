"""Broadcast arguments read in place: a call over the leading shape runs as
segments (its outer axes) of contiguous inner runs (its inner axes), and
each argument is passed in its compact form (its stride-0 and size-1 axes of
size 1), read by the C++ batch layer at an offset a segment
(``Segments`` in batch.hpp). Within a segment an argument is one value (a
vector) or contiguous; one that is neither along the inner axes is expanded
along those axes only.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import NDArray

# Inner runs shorter than this are not worth a segment: the padded tail of
# each run (at most one SIMD batch) would cost more than a copy saves.
SMALLEST_SEGMENT = 256


def unexpanded(array: NDArray[Any]) -> NDArray[Any]:
    """``array`` with every stride-0 axis (a broadcast view's) cut to size 1: a view
    of the values it holds (``np.broadcast_to(unexpanded(a), a.shape)`` is ``a``)."""
    return array[tuple(slice(0, 1) if stride == 0 and size > 1 else slice(None)
                       for stride, size in zip(array.strides, array.shape))]


def compact(array: NDArray[np.float32], depth: int, vector_axis: int | None) -> NDArray[np.float32]:
    """``array`` with its leading axes (all but ``vector_axis``: 0, -1 or None)
    padded in front to ``depth`` and each stride-0 one cut to size 1: a view."""
    vector = () if vector_axis is None else (3,)
    own = array.shape if vector_axis is None else array.shape[1:] if vector_axis == 0 else array.shape[:-1]
    padded = (1,) * (depth - len(own)) + own
    shape = vector + padded if vector_axis == 0 else padded + vector
    view = array.reshape(shape)
    axes = range(1, depth + 1) if vector_axis == 0 else range(depth)
    index = [slice(None)] * view.ndim
    for axis in axes:
        if view.strides[axis] == 0 and view.shape[axis] > 1:
            index[axis] = slice(0, 1)
    return view[tuple(index)]


def leading_of(view: NDArray[np.float32], vector_axis: int | None) -> tuple[int, ...]:
    return view.shape if vector_axis is None else view.shape[1:] if vector_axis == 0 else view.shape[:-1]


def choose_split(leading: tuple[int, ...], shapes: list[tuple[int, ...]]) -> int:
    """The number of outer axes: the split that expands the fewest elements,
    among those whose inner runs are long enough (no split always qualifies),
    the fewest segments on a tie."""
    best_cost, best = None, 0
    for split in range(len(leading) + 1):
        inner = leading[split:]
        if split > 0 and math.prod(inner) < SMALLEST_SEGMENT:
            break
        ones = (1,) * len(inner)
        cost = sum(math.prod(shape[:split]) * math.prod(inner) for shape in shapes if shape[split:] not in (inner, ones))
        if best_cost is None or cost < best_cost:
            best_cost, best = cost, split
    return best


class Part(NamedTuple):
    array: NDArray[np.float32]  # C-contiguous, the compact argument (expanded along the inner axes if needed)
    single: bool                # one value (vector) a segment
    offsets: NDArray[np.int64] | None  # elements from the array's start to each segment's, or None for 0


def part(view: NDArray[np.float32], leading: tuple[int, ...], split: int, vector_axis: int | None) -> Part:
    """An argument's compact view (``compact``) as a segmented call reads it."""
    shape = leading_of(view, vector_axis)
    inner = leading[split:]
    ones = (1,) * len(inner)
    if shape[split:] not in (inner, ones):  # expanded along the inner axes only
        target = shape[:split] + inner
        view = np.broadcast_to(view, (3,) + target if vector_axis == 0 else target + (() if vector_axis is None else (3,)))
        shape = target
    single = shape[split:] == ones
    array = np.ascontiguousarray(view, dtype=np.float32)
    outer = shape[:split]
    if all(size == 1 for size in outer):
        return Part(array, single, None)
    grid = np.arange(math.prod(outer), dtype=np.int64).reshape(outer)
    index = np.ascontiguousarray(np.broadcast_to(grid, leading[:split])).reshape(-1)
    return Part(array, single, index * (1 if single else math.prod(inner)))
