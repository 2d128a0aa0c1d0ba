"""Type stubs of the compiled extension `smoothtrace._native` (python/src/). Use the
package's functions (`smoothtrace.SmoothDistance`, ...): they convert and check dtypes
and shapes, then call these with C-contiguous float64 / int64 arrays."""

from typing import List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

F64 = npt.NDArray[np.float64]
I64 = npt.NDArray[np.int64]
U8 = npt.NDArray[np.uint8]

def load_mesh(path: str) -> Tuple[F64, I64, I64]: ...

class SmoothDistance:
    def __init__(
        self,
        vertices: F64,
        faces: Optional[I64],
        edges: Optional[I64],
        primitives: List[str],
        alpha: Optional[float],
        alpha_rel: Optional[float],
        max_alpha: Optional[float],
        max_alpha_rel: Optional[float],
        beta: float,
        tolerance: Optional[float] = None,
    ) -> None: ...
    def value(self, points: F64, threads: Optional[int] = None) -> F64: ...
    def value_bounds(self, points: F64, threads: Optional[int] = None) -> Tuple[F64, F64]: ...
    def value_and_gradient(self, points: F64, threads: Optional[int] = None) -> Tuple[F64, F64]: ...
    def nearest(self, points: F64, threads: Optional[int] = None) -> Tuple[F64, I64, F64, I64]: ...
    @property
    def alpha(self) -> float: ...
    @property
    def max_alpha(self) -> float: ...
    @property
    def beta(self) -> float: ...
    @property
    def primitives(self) -> List[str]: ...
    @property
    def counts(self) -> List[int]: ...
    @property
    def edges(self) -> I64: ...

def distance_field(
    vertices: F64,
    faces: Optional[I64],
    edges: Optional[I64],
    primitive: str,
    bounds: Optional[Sequence[float]],
    resolution: List[int],
    method: str,
    smooth_alpha: Optional[float],
    smooth_alpha_rel: Optional[float],
    max_alpha: Optional[float],
    beta: Optional[float],
    band: Optional[float],
    threads: Optional[int],
) -> Tuple[F64, List[float], List[float]]: ...

class FieldPlan:
    """A field prepared once, computed box by box (`smoothtrace.dask`)."""

    def __init__(
        self,
        vertices: F64,
        faces: Optional[I64],
        edges: Optional[I64],
        primitive: str,
        bounds: Optional[Sequence[float]],
        resolution: List[int],
        method: str,
        smooth_alpha: Optional[float],
        smooth_alpha_rel: Optional[float],
        max_alpha: Optional[float],
        beta: Optional[float],
        band: Optional[float],
        threads: Optional[int],
    ) -> None: ...
    def grid(self) -> Tuple[List[float], List[float], List[int]]: ...
    def compute_box(self, start: Sequence[int], size: Sequence[int]) -> np.ndarray: ...

def render(
    scene: str,
    width: Optional[int] = None,
    height: Optional[int] = None,
    beta: Optional[float] = None,
    alpha: Optional[float] = None,
    alpha_rel: Optional[float] = None,
    threads: Optional[int] = None,
) -> U8: ...
def render_arrays(
    vertices: F64,
    faces: Optional[I64],
    edges: Optional[I64],
    primitives: List[str],
    alpha: Optional[float],
    alpha_rel: Optional[float],
    max_alpha: Optional[float],
    max_alpha_rel: Optional[float],
    beta: float,
    camera: Optional[Tuple[List[float], List[float], List[float], Optional[float]]],
    matcap: str,
    width: int,
    height: int,
    background: List[int],
    threads: Optional[int],
) -> U8: ...
def winding_number(
    vertices: F64, faces: I64, points: F64, beta: float, threads: Optional[int] = None
) -> F64: ...
def signed_distance(
    vertices: F64, faces: I64, points: F64, beta: float, threads: Optional[int] = None
) -> Tuple[F64, I64, F64]: ...
def _panic_for_tests(message: str) -> None: ...
