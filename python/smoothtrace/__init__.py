"""Smooth distances to point clouds, edge meshes and triangle meshes, as numpy arrays.

The smooth distance of Madan and Levin (SIGGRAPH 2022) is a weighted LogSumExp
("smooth minimum") of the exact distances ``d_i`` to the primitives::

    s(x) = -(1/alpha) ln( sum_i w_i exp(-alpha d_i) )

It never exceeds the distance to the nearest primitive; larger ``alpha`` hugs the data,
smaller ``alpha`` gives puffy, closed surfaces. ``beta`` is the Barnes-Hut opening
parameter (0 = the exact sum; larger is faster, and the value stays a lower bound of the
exact one).

Arrays in and out are numpy arrays: points of shape ``(n, 3)`` float64 (integer and
float32 arrays are converted; other dtypes are rejected), faces ``(m, 3)`` and edges
``(k, 2)`` of integer vertex indices. Work runs in Rust on rayon threads with the GIL
released; ``threads=`` picks the number of threads for one call (``0`` = all cores, the
default ``None`` = rayon's global pool, all cores). Bad input raises ``ValueError`` with
the same message as the ``smoothtrace`` command line; files that cannot be read raise
``FileNotFoundError`` or ``OSError``.

>>> import smoothtrace as st
>>> V, F = st.load_mesh("bunny.obj")
>>> sd = st.SmoothDistance(V, faces=F, alpha_rel=1000)
>>> s, g = sd.value_and_gradient(V[:10] + 0.01)
"""

from __future__ import annotations

import collections.abc as _abc
import numbers as _numbers
import os as _os
import typing as _typing

import numpy as _np

from . import _native
from ._native import __version__

if _typing.TYPE_CHECKING:
    # Names for the annotations only (they are not evaluated at run time, see the
    # `__future__` import), so that the package's namespace holds its API alone.
    import os
    from typing import Any, List, Mapping, Optional, Sequence, Tuple, Union

    import numpy as np

# The `__future__` import above binds `annotations` in the module; the compiler flag is
# all it is for.
del annotations

# The public API, one name a line; `dir(smoothtrace)` lists exactly these (see `__dir__`).
__all__ = [
    "SmoothDistance",
    "distance_field",
    "load_mesh",
    "render",
    "render_arrays",
    "signed_distance",
    "winding_number",
    "__version__",
]


def __dir__() -> List[str]:
    """The public API (``__all__``): what tab completion and ``dir(smoothtrace)`` show."""
    return sorted(__all__)

_KINDS = ("points", "edges", "triangles")


def _coordinates(a: Any, name: str) -> np.ndarray:
    """`a` as a C-contiguous float64 array of shape (n, 3)."""
    arr = _np.asarray(a)
    if arr.dtype.kind not in "fiu":
        raise ValueError(
            f"{name} must hold real numbers (a float or integer array), got dtype {arr.dtype}"
        )
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n, 3), got {arr.shape}")
    return _np.ascontiguousarray(arr, dtype=_np.float64)


def _indices(a: Any, name: str, width: int) -> Optional[np.ndarray]:
    """`a` as a C-contiguous int64 array of shape (n, width), or None."""
    if a is None:
        return None
    arr = _np.asarray(a)
    if arr.size == 0 and arr.dtype.kind == "f":
        # An empty list becomes a float array; it holds no indices to misread.
        arr = arr.astype(_np.int64)
    if arr.dtype.kind not in "iu":
        raise ValueError(
            f"{name} must be an integer array of vertex indices, got dtype {arr.dtype}"
        )
    if arr.ndim != 2 or arr.shape[1] != width:
        raise ValueError(f"{name} must have shape (n, {width}), got {arr.shape}")
    if arr.dtype.kind == "u" and arr.size and arr.max() > _np.iinfo(_np.int64).max:
        raise ValueError(f"{name} holds vertex index {arr.max()}, out of range")
    return _np.ascontiguousarray(arr, dtype=_np.int64)


def _primitives(
    primitives: Union[None, str, Sequence[str]], faces: Any, edges: Any
) -> List[str]:
    """The primitive sets to build: given, or what the arrays provide."""
    if primitives is None:
        if faces is not None:
            return ["triangles"]
        if edges is not None:
            return ["edges"]
        return ["points"]
    names = [primitives] if isinstance(primitives, str) else list(primitives)
    out = []
    for n in names:
        for part in str(n).split(","):
            part = part.strip()
            if part not in _KINDS:
                raise ValueError(
                    f"unknown primitive type '{part}': expected points, edges or triangles"
                )
            out.append(part)
    return out


def _number(v: Any, name: str) -> Optional[float]:
    """A real number as float (None stays None); anything else is a ValueError."""
    if v is None:
        return None
    if isinstance(v, bool) or not isinstance(v, _numbers.Real):
        raise ValueError(f"{name} must be a number (got {v!r})")
    return float(v)


def _threads(threads: Any) -> Optional[int]:
    """A thread count as int (None: rayon's global pool); the range is checked in Rust."""
    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, _numbers.Integral):
        raise ValueError(f"threads must be an integer (got {threads!r})")
    return int(threads)


def _alpha_args(alpha, alpha_rel, max_alpha, max_alpha_rel):
    """The four alpha arguments as floats; an absolute and a relative value exclude each
    other. Their ranges are checked in Rust, with the command line's messages."""
    if alpha is not None and alpha_rel is not None:
        raise ValueError("give alpha or alpha_rel, not both")
    if max_alpha is not None and max_alpha_rel is not None:
        raise ValueError("give max_alpha or max_alpha_rel, not both")
    return (
        _number(alpha, "alpha"),
        _number(alpha_rel, "alpha_rel"),
        _number(max_alpha, "max_alpha"),
        _number(max_alpha_rel, "max_alpha_rel"),
    )


def load_mesh(
    path: Union[str, "os.PathLike[str]"], return_edges: bool = False
) -> Union[Tuple[np.ndarray, np.ndarray], Tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Read a mesh file (OBJ, PLY or STL, chosen by extension).

    Returns ``(V, F)``: vertices ``(nv, 3)`` float64 and triangles ``(nf, 3)`` int64
    (polygons are fan-triangulated; ``(0, 3)`` for a point cloud or an edge mesh). With
    ``return_edges=True`` returns ``(V, F, E)`` with the file's explicit segments ``(ne,
    2)`` int64 (OBJ ``l`` lines, PLY ``edge`` elements). Coordinates are stored as
    float32 in the library, so ``V`` holds float32 values widened to float64.

    Raises ``FileNotFoundError`` for a missing file, ``OSError`` for an unreadable one and
    ``ValueError`` (naming the file and line) for malformed contents, an unknown
    extension, non-finite coordinates or out-of-range indices.
    """
    V, F, E = _native.load_mesh(str(path))
    return (V, F, E) if return_edges else (V, F)


class SmoothDistance:
    """The smooth distance of a mesh's primitive sets, built once and queried many times.

    Parameters
    ----------
    V : (n, 3) array
        Vertex positions (stored as float32, as in the command line).
    faces : (m, 3) int array, optional
        Triangles; needed for ``primitives="triangles"`` and the source of edges when no
        ``edges`` are given.
    edges : (k, 2) int array, optional
        Explicit segments; used for ``primitives="edges"`` instead of the faces' edges.
    primitives : str or list of str, optional
        ``"points"``, ``"edges"``, ``"triangles"`` or several (a list, or comma
        separated) whose sums are added into one smooth distance. Default: triangles
        when ``faces`` is given, else edges when ``edges`` is given, else points.
    alpha : float, optional
        Sharpness (1/length). Give ``alpha`` or ``alpha_rel``.
    alpha_rel : float, optional
        Sharpness relative to the bounding-box diagonal: ``alpha = alpha_rel / diagonal``.
    max_alpha, max_alpha_rel : float, optional
        Weight attenuation threshold (SPEC 5); default ``alpha``.
    beta : float
        Barnes-Hut opening parameter in [0, 1]; 0 is the exact sum. Default 0.5.
    tolerance : float, optional
        How far pruning (skipping subtrees too far to matter) may lower the smooth
        distance at most, in the mesh's units; 0 turns pruning off. Default: subtrees
        holding together 1e-10 of the sum, within ``2e-10 / alpha``. A looser one is
        faster near the surface: on the full Stanford bunny at ``alpha_rel=1000``,
        ``1e-7 * diagonal`` took :meth:`value` 2.5x less time (README, "Python").

    Only the requested sets are built (with their BVHs), as in the command line.
    """

    def __init__(
        self,
        V: Any,
        faces: Any = None,
        edges: Any = None,
        primitives: Union[None, str, Sequence[str]] = None,
        alpha: Optional[float] = None,
        alpha_rel: Optional[float] = None,
        max_alpha: Optional[float] = None,
        max_alpha_rel: Optional[float] = None,
        beta: float = 0.5,
        tolerance: Optional[float] = None,
    ) -> None:
        kinds = _primitives(primitives, faces, edges)
        a, ar, m, mr = _alpha_args(alpha, alpha_rel, max_alpha, max_alpha_rel)
        beta_value = _number(beta, "beta")
        self._native = _native.SmoothDistance(
            _coordinates(V, "V"),
            _indices(faces, "faces", 3),
            _indices(edges, "edges", 2),
            kinds,
            a,
            ar,
            m,
            mr,
            0.5 if beta_value is None else beta_value,
            _number(tolerance, "tolerance"),
        )

    def value(self, P: Any, threads: Optional[int] = None) -> np.ndarray:
        """The smooth distance at each row of ``P`` ((n, 3)): an (n,) float64 array."""
        return self._native.value(_coordinates(P, "P"), _threads(threads))

    def value_bounds(
        self, P: Any, threads: Optional[int] = None
    ) -> Tuple[np.ndarray, np.ndarray]:
        """The smooth distance at each row of ``P`` with a certified interval around the
        exact (beta 0) value: ``(lower, upper)``, two (n,) float64 arrays with ``lower <=
        exact <= upper``. ``lower`` is the Barnes-Hut sum (as ``value`` gives it, but for
        point clouds, whose far terms here bound from the closest box, not from moments);
        ``upper`` takes every far-field subtree at its lower bound. Their difference says
        how much ``beta`` costs in accuracy at each point."""
        return self._native.value_bounds(_coordinates(P, "P"), _threads(threads))

    def value_and_gradient(
        self, P: Any, threads: Optional[int] = None
    ) -> Tuple[np.ndarray, np.ndarray]:
        """The smooth distance ``(n,)`` and its exact gradient ``(n, 3)`` at each row of
        ``P``. The gradient includes the weights' terms (SPEC 5)."""
        return self._native.value_and_gradient(_coordinates(P, "P"), _threads(threads))

    def nearest(
        self, P: Any, threads: Optional[int] = None, return_set: bool = False
    ) -> Union[
        Tuple[np.ndarray, np.ndarray, np.ndarray],
        Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    ]:
        """The exact nearest primitive to each row of ``P``.

        Returns ``(d, idx, closest)``: the exact distance ``(n,)`` float64, the index
        ``(n,)`` int64 of the primitive in its set (a vertex index for points, a row of
        :attr:`edges` for edges, a row of ``faces`` for triangles) and the closest point
        ``(n, 3)`` float64. With several primitive sets, ``return_set=True`` appends the
        position ``(n,)`` int64 of each point's set in :attr:`primitives`.
        """
        d, idx, closest, which = self._native.nearest(
            _coordinates(P, "P"), _threads(threads)
        )
        return (d, idx, closest, which) if return_set else (d, idx, closest)

    @property
    def alpha(self) -> float:
        """The resolved alpha (1/length)."""
        return self._native.alpha

    @property
    def max_alpha(self) -> float:
        """The resolved max_alpha (1/length)."""
        return self._native.max_alpha

    @property
    def beta(self) -> float:
        """The Barnes-Hut opening parameter."""
        return self._native.beta

    @property
    def primitives(self) -> List[str]:
        """The primitive sets summed, in order (duplicates removed)."""
        return self._native.primitives

    @property
    def counts(self) -> List[int]:
        """The number of primitives in each set."""
        return self._native.counts

    @property
    def edges(self) -> np.ndarray:
        """The ``(k, 2)`` vertex indices of the edge set (the explicit edges, else the
        faces' unique edges, sorted); empty when no edge set was built."""
        return self._native.edges

    def __repr__(self) -> str:
        sets = ", ".join(f"{k} ({n})" for k, n in zip(self.primitives, self.counts))
        return (
            f"SmoothDistance({sets}, alpha={self.alpha:g}, "
            f"max_alpha={self.max_alpha:g}, beta={self.beta:g})"
        )


def _faces(F: Any) -> np.ndarray:
    """Faces for the winding-number functions: required, shape (m, 3)."""
    if F is None:
        raise ValueError("F is required: the triangles (m, 3) whose winding number is taken")
    return _indices(F, "F", 3)


def winding_number(
    V: Any, F: Any, P: Any, threads: Optional[int] = None, beta: float = 0.3
) -> np.ndarray:
    """The generalized winding number of the triangles ``(V, F)`` at each row of ``P``.

    ``w = sum of the triangles' signed solid angles / (4 pi)``: 1 inside and 0 outside a
    closed mesh with outward (counter-clockwise) faces, and a smooth inside-outside
    measure (inside where ``w > 1/2``) on open or non-manifold soups. Computed by the
    Barnes-Hut method of Barill et al. (SIGGRAPH 2018) on a BVH: a node whose radius is
    below ``beta`` times its distance to the query is replaced by its second-order
    far-field expansion. ``beta = 0`` is the exact sum; the default 0.3 stays within 1e-3
    of it at points farther than 1e-3 of the diagonal from the surface (libigl's default
    ``accuracy_scale = 2`` is ``beta = 0.5``). Returns an ``(n,)`` float64 array.

    Raises ``ValueError`` naming the argument and row for bad input (non-finite values,
    query coordinates beyond 1e31, out-of-range face indices).
    """
    return _native.winding_number(
        _coordinates(V, "V"),
        _faces(F),
        _coordinates(P, "P"),
        _number(beta, "beta"),
        _threads(threads),
    )


def signed_distance(
    V: Any, F: Any, P: Any, threads: Optional[int] = None, beta: float = 0.3
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The exact distance from each row of ``P`` to the triangles ``(V, F)``, negative
    inside (where the fast winding number, see :func:`winding_number`, exceeds 1/2).

    Returns ``(S, idx, closest)`` like :meth:`SmoothDistance.nearest`: the signed distance
    ``(n,)`` float64 (``abs(S)`` is the exact unsigned distance), the index ``(n,)`` int64
    of the nearest face and the closest point ``(n, 3)`` float64.
    """
    return _native.signed_distance(
        _coordinates(V, "V"),
        _faces(F),
        _coordinates(P, "P"),
        _number(beta, "beta"),
        _threads(threads),
    )


def _field_args(
    V, faces, edges, primitive, bounds, resolution, smooth_alpha, smooth_alpha_rel,
    max_alpha, beta, method, band, threads,
) -> tuple:
    """The checked arguments of ``_native.distance_field`` and ``_native.FieldPlan``."""
    kind = _primitives(primitive, faces, edges)
    if len(kind) != 1:
        raise ValueError(f"distance_field takes one primitive type (got {kind})")
    if bounds is not None:
        b = _np.asarray(bounds, dtype=_np.float64).reshape(-1)
        if b.shape != (6,):
            raise ValueError(
                f"bounds must be [xmin, ymin, zmin, xmax, ymax, zmax] or [[min], [max]] (got {_np.shape(bounds)})"
            )
        bounds = [float(x) for x in b]
    if isinstance(resolution, _numbers.Integral):
        res = [int(resolution)]
    else:
        res = [int(r) for r in resolution]
    if smooth_alpha is not None and smooth_alpha_rel is not None:
        raise ValueError("give smooth_alpha or smooth_alpha_rel, not both")
    return (
        _coordinates(V, "V"),
        _indices(faces, "faces", 3),
        _indices(edges, "edges", 2),
        kind[0],
        bounds,
        res,
        str(method),
        _number(smooth_alpha, "smooth_alpha"),
        _number(smooth_alpha_rel, "smooth_alpha_rel"),
        _number(max_alpha, "max_alpha"),
        0.5 if beta is None else _number(beta, "beta"),
        _number(band, "band"),
        _threads(threads),
    )


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
    threads: Optional[int] = None,
    return_bounds: bool = False,
) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]:
    """A distance volume on a voxel grid (SPEC 9), as ``smoothtrace field`` computes it.

    Voxel ``(i, j, k)`` has its centre at ``min + ((i, j, k) + 0.5) * (max - min) / (nx,
    ny, nz)``; the result is a float64 array of shape ``(nz, ny, nx)`` (the command
    line's ``.npy`` layout; the values are the library's float32 values, widened).

    Parameters
    ----------
    primitive : str, optional
        ``"points"``, ``"edges"`` or ``"triangles"``; default as in
        :class:`SmoothDistance`.
    bounds : (2, 3) or (6,) array, optional
        ``[min, max]`` corners. Default: the mesh's box grown by 10% of its diagonal on
        every side.
    resolution : int or (nx, ny, nz)
        One integer: cubic voxels, that many along the longest axis (the other axes'
        extent grows symmetrically to a whole number of voxels). Three: the counts per
        axis, the bounds kept as given.
    smooth_alpha, smooth_alpha_rel : float, optional
        Store the smooth distance at this alpha (absolute, or relative to the diagonal)
        instead of the exact distance; ``max_alpha`` and ``beta`` apply then.
    method : str
        Exact method: ``"linfac"`` (default, linear factorization), ``"bvh"`` (a nearest
        query per voxel) or ``"brute"`` (every primitive at every voxel).
    band : float, optional
        Exact values where ``d <= band``, ``inf`` elsewhere.
    return_bounds : bool
        Also return the grid's ``(2, 3)`` ``[min, max]`` corners.
    """
    field, lo, hi = _native.distance_field(
        *_field_args(
            V, faces, edges, primitive, bounds, resolution, smooth_alpha,
            smooth_alpha_rel, max_alpha, beta, method, band, threads,
        )
    )
    if return_bounds:
        return field, _np.array([lo, hi], dtype=_np.float64)
    return field


def render(
    scene: Union[str, "os.PathLike[str]"],
    width: Optional[int] = None,
    height: Optional[int] = None,
    beta: Optional[float] = None,
    alpha: Optional[float] = None,
    alpha_rel: Optional[float] = None,
    threads: Optional[int] = None,
) -> np.ndarray:
    """Render a scene file (TOML, see the README) as ``smoothtrace render`` does.

    The keyword arguments override the scene's values as the command line's flags do
    (``alpha``/``alpha_rel`` replace every object's). Returns a ``(height, width, 4)``
    uint8 RGBA array (alpha 255 everywhere), the same pixels as the command line's PNG.
    """
    return _native.render(
        str(scene),
        width,
        height,
        _number(beta, "beta"),
        _number(alpha, "alpha"),
        _number(alpha_rel, "alpha_rel"),
        _threads(threads),
    )


def _camera(camera: Any):
    """A camera dict as (origin, target, up, fov) for the extension, or None."""
    if camera is None:
        return None
    if isinstance(camera, _abc.Mapping):
        unknown = set(camera) - {"origin", "target", "up", "fov"}
        if unknown:
            raise ValueError(
                f"unknown camera key(s) {sorted(unknown)}: expected origin, target, up, fov"
            )
        if "origin" not in camera or "target" not in camera:
            raise ValueError("camera needs 'origin' and 'target'")
        parts = (
            camera["origin"],
            camera["target"],
            camera.get("up", (0.0, 1.0, 0.0)),
            camera.get("fov", 53.13),
        )
    else:
        raise ValueError(
            "camera must be a dict with 'origin', 'target' and optionally 'up', 'fov'"
        )
    vecs = []
    for name, v in zip(("origin", "target", "up"), parts[:3]):
        a = _np.asarray(v, dtype=_np.float64).reshape(-1)
        if a.shape != (3,):
            raise ValueError(f"camera {name} must be three numbers (got {v!r})")
        vecs.append([float(x) for x in a])
    return (vecs[0], vecs[1], vecs[2], _number(parts[3], "camera fov"))


def _background(bg: Any):
    """Three integers 0 to 255."""
    try:
        c = [int(x) for x in bg]
    except (TypeError, ValueError):
        c = []
    if len(c) != 3 or any(not 0 <= x <= 255 for x in c):
        raise ValueError(f"background must be three integers 0 to 255 (got {bg!r})")
    return c


def render_arrays(
    V: Any,
    faces: Any = None,
    edges: Any = None,
    primitives: Union[None, str, Sequence[str]] = None,
    alpha: Optional[float] = None,
    alpha_rel: Optional[float] = None,
    max_alpha: Optional[float] = None,
    max_alpha_rel: Optional[float] = None,
    beta: float = 0.5,
    camera: Optional[Mapping[str, Any]] = None,
    matcap: str = "clay",
    width: int = 960,
    height: int = 540,
    background: Sequence[int] = (255, 255, 255),
    threads: Optional[int] = None,
) -> np.ndarray:
    """Render the smooth surface (the zero level set) of a mesh given as arrays.

    The mesh arguments and ``alpha``, ``alpha_rel``, ``max_alpha``, ``beta`` are those of
    :class:`SmoothDistance`. ``camera`` is a dict with ``origin``, ``target`` and
    optionally ``up`` (default ``[0, 1, 0]``) and ``fov`` (vertical, degrees, default
    53.13); by default the camera looks at the centre of the mesh's box from the front
    (+z) and a little above, far enough to see all the surface can reach. ``matcap``
    is a built-in name (clay, blue, jade, gold, white), ``"normal"``, or a PNG path. The
    hit threshold and step limit are the scene-file defaults (4e-4 of the diagonal,
    1000 steps). Returns a ``(height, width, 4)`` uint8 RGBA array (alpha 255).
    """
    kinds = _primitives(primitives, faces, edges)
    a, ar, m, mr = _alpha_args(alpha, alpha_rel, max_alpha, max_alpha_rel)
    beta_value = _number(beta, "beta")
    return _native.render_arrays(
        _coordinates(V, "V"),
        _indices(faces, "faces", 3),
        _indices(edges, "edges", 2),
        kinds,
        a,
        ar,
        m,
        mr,
        0.5 if beta_value is None else beta_value,
        _camera(camera),
        str(matcap),
        int(width),
        int(height),
        _background(background),
        _threads(threads),
    )
