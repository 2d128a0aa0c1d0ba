"""Distance volumes and batches of meshes on Dask (``pip install "smoothtrace[dask]"``).

:func:`distance_field` returns a lazy :class:`dask.array.Array` of the volume that
:func:`smoothtrace.distance_field` computes, in blocks of ``chunks`` voxels: each block
is computed by the library (Rust, the GIL released) from a field prepared once per
worker process, so ``dask.distributed`` spreads one volume over the cores of many
machines, and ``.to_zarr(...)`` writes it block by block without holding it in memory::

    import smoothtrace as st, smoothtrace.dask as sdask
    from dask.distributed import Client, LocalCluster

    V, F = st.load_mesh("bunny.obj")
    client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
    vol = sdask.distance_field(V, F, resolution=1024, chunks=128)
    vol.to_zarr("bunny.zarr")             # zarr-python writes the blocks as they finish

:func:`map_meshes` runs one function per mesh file as a :class:`dask.bag.Bag` (each task
loads its mesh on the worker, so only paths and results travel)::

    sizes = sdask.map_meshes(paths, lambda path, V, F: (path, len(F))).compute()

Dask (with ``distributed`` for clusters) is an optional extra: this module raises an
``ImportError`` naming it when dask is missing; ``import smoothtrace`` never needs it.
"""

from __future__ import annotations

import numbers
import os
from typing import Any, Callable, Iterable, Optional, Sequence, Tuple, Union

import numpy as np

try:
    import dask.array as _da
    import dask.bag as _db
    from dask.base import tokenize as _tokenize
except ImportError as _e:  # pragma: no cover - depends on the environment
    raise ImportError(
        "smoothtrace.dask needs dask (dask.array and dask.bag): "
        'pip install "smoothtrace[dask]" (dask, distributed and zarr)'
    ) from _e

from . import _field_args, _native, load_mesh

__all__ = ["distance_field", "map_meshes"]


class _Blocks:
    """The field's arguments, and the prepared field built from them on first use in each
    process (pickling sends only the arguments; the sites or BVH are built again where
    the blocks are computed, once per worker process)."""

    def __init__(self, args: tuple, plan: Any = None):
        self.args = args
        self._plan = plan

    def __getstate__(self):
        return {"args": self.args}

    def __setstate__(self, state):
        self.args = state["args"]
        self._plan = None

    def plan(self):
        if self._plan is None:
            self._plan = _native.FieldPlan(*self.args)
        return self._plan


def _block(blocks: _Blocks, start: Tuple[int, int, int], size: Tuple[int, int, int]):
    return blocks.plan().compute_box(start, size)


def _chunk_sizes(n: int, c: int) -> Tuple[int, ...]:
    return tuple(min(c, n - s) for s in range(0, n, c))


def distance_field(
    V: Any,
    faces: Any = None,
    edges: Any = None,
    primitive: Optional[str] = None,
    bounds: Any = None,
    resolution: Union[int, Sequence[int]] = 64,
    smooth_alpha: Optional[float] = None,
    smooth_alpha_rel: Optional[float] = None,
    max_alpha: Optional[float] = None,
    beta: float = 0.5,
    method: str = "linfac",
    band: Optional[float] = None,
    chunks: Union[int, Sequence[int]] = 128,
    threads: Optional[int] = None,
    return_bounds: bool = False,
):
    """The volume of :func:`smoothtrace.distance_field` as a lazy dask array.

    The arguments are those of :func:`smoothtrace.distance_field`, plus ``chunks``: the
    block edge in voxels (one integer for cubic blocks, or ``(cz, cy, cx)``), each at
    least 1 and cut to the volume. The array has shape ``(nz, ny, nx)`` and dtype
    float32 (the library's values; :func:`smoothtrace.distance_field` widens them to
    float64), so it matches the command line's ``.npy`` and ``.zarr`` outputs.
    ``threads`` is the number of threads inside one block (default: all cores of the
    worker; with several worker processes on one machine give ``threads=1``).

    The arguments are checked and the field is prepared once here (errors raise
    ``ValueError`` at once, not when the graph runs); the blocks are computed when the
    array is computed or stored. ``return_bounds=True`` also returns the grid's
    ``(2, 3)`` ``[min, max]`` corners.
    """
    args = _field_args(
        V, faces, edges, primitive, bounds, resolution, smooth_alpha,
        smooth_alpha_rel, max_alpha, beta, method, band, threads,
    )
    plan = _native.FieldPlan(*args)
    lo, hi, (nx, ny, nz) = plan.grid()
    if isinstance(chunks, numbers.Integral):
        cz = cy = cx = int(chunks)
    else:
        c = [int(x) for x in chunks]
        if len(c) != 3:
            raise ValueError(f"chunks must be one integer or three (cz, cy, cx); got {len(c)} values")
        cz, cy, cx = c
    for name, v in (("cz", cz), ("cy", cy), ("cx", cx)):
        if v < 1:
            raise ValueError(f"chunks must be at least 1 voxel (got {name} = {v})")
    sizes = (_chunk_sizes(nz, cz), _chunk_sizes(ny, cy), _chunk_sizes(nx, cx))
    token = _tokenize(*args[:3], args[3:], chunks)
    name = "smoothtrace-distance-field-" + token
    blocks_key = "smoothtrace-field-plan-" + token
    graph: dict = {blocks_key: _Blocks(args, plan)}
    z0 = 0
    for iz, sz in enumerate(sizes[0]):
        y0 = 0
        for iy, sy in enumerate(sizes[1]):
            x0 = 0
            for ix, sx in enumerate(sizes[2]):
                graph[(name, iz, iy, ix)] = (_block, blocks_key, (x0, y0, z0), (sx, sy, sz))
                x0 += sx
            y0 += sy
        z0 += sz
    vol = _da.Array(graph, name, chunks=sizes, dtype=np.float32)
    if return_bounds:
        return vol, np.array([lo, hi], dtype=np.float64)
    return vol


def _apply(path: str, fn: Callable, return_edges: bool):
    mesh = load_mesh(path, return_edges=return_edges)
    return fn(path, *mesh)


def map_meshes(
    paths: Iterable[Union[str, "os.PathLike[str]"]],
    fn: Callable[..., Any],
    return_edges: bool = False,
    npartitions: Optional[int] = None,
):
    """A :class:`dask.bag.Bag` of ``fn(path, V, F)`` (``fn(path, V, F, E)`` with
    ``return_edges=True``) for each mesh file, loaded with :func:`smoothtrace.load_mesh`
    on the worker that runs it. ``fn`` may write a field or samples next to the mesh and
    return a small summary; ``.compute()`` returns the results in the order of
    ``paths``. ``npartitions`` defaults to one task per mesh.
    """
    paths = [os.fspath(p) for p in paths]
    if not paths:
        raise ValueError("map_meshes needs at least one mesh path")
    n = len(paths) if npartitions is None else int(npartitions)
    return _db.from_sequence(paths, npartitions=n).map(_apply, fn, return_edges)
