# Type stub of voronoi_fit (the package's docstrings say what each function does).
import os
from pathlib import Path
from typing import Any, Callable, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

MeshLike = Union[
    Tuple[npt.ArrayLike, npt.ArrayLike],  # (vertices (n, 3), faces (m, 3))
    "FitResult",  # its crust
    str,
    os.PathLike[str],  # a mesh file
    Any,  # anything with .vertices and .faces (trimesh.Trimesh)
]
Progress = Callable[[str, int, int, float], Any]

class InputError(ValueError): ...
class Error(RuntimeError): ...

class FitResult:
    sites: npt.NDArray[np.float64]
    labels: npt.NDArray[np.bool_]
    sites_unit: npt.NDArray[np.float64]
    transform: npt.NDArray[np.float64]
    crust_vertices: npt.NDArray[np.float64]
    crust_faces: npt.NDArray[np.uint32]
    report: dict[str, Any]
    def to_trimesh(self) -> Any: ...
    def save(self, prefix: Union[str, os.PathLike[str]], format: str = "glb", normals: str = "flat") -> dict[str, str]: ...
    def summary(self) -> str: ...

def load_mesh(path: Union[str, os.PathLike[str]]) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]: ...
def fit(
    mesh: Union[MeshLike, npt.ArrayLike],
    faces: Optional[npt.ArrayLike] = None,
    *,
    sites: int = 8192,
    seed: int = 0,
    relabel: bool = True,
    carve: Union[float, bool] = True,
    prune: bool = True,
    progress: Union[Progress, bool, None] = None,
    name: Optional[str] = None,
    float32: bool = True,
    steps: Optional[int] = None,
    preset: Optional[str] = None,
    init: Optional[str] = None,
    batch: Optional[int] = None,
    lr: Optional[float] = None,
    beta_start: Optional[float] = None,
    surface_offset: Optional[float] = None,
    w_sdf: Optional[float] = None,
    w_centroidal: Optional[float] = None,
    w_normal: Optional[float] = None,
    w_reconstruction: Optional[float] = None,
    w_surface: Optional[float] = None,
    samples: Optional[int] = None,
    eval_samples: Optional[int] = None,
    solid: Optional[str] = None,
    shell_thickness: Optional[float] = None,
    no_fill_holes: Optional[bool] = None,
    train_shell: Optional[bool] = None,
    skip_metrics: Optional[bool] = None,
    polish_steps: Optional[int] = None,
    polish_lr: Optional[float] = None,
    polish_batch: Optional[int] = None,
    polish_align: Optional[float] = None,
) -> FitResult: ...
def save_mesh(
    path: Union[str, os.PathLike[str]], vertices: npt.ArrayLike, faces: npt.ArrayLike, normals: str = "flat"
) -> None: ...
def crust(
    sites: npt.ArrayLike, labels: npt.ArrayLike, transform: Optional[npt.ArrayLike] = None
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]: ...
def winding_number(
    V: Any, F: npt.ArrayLike, Q: Optional[npt.ArrayLike] = None, exact: bool = False
) -> npt.NDArray[np.float64]: ...
def signed_distance(
    V: Any, F: npt.ArrayLike, Q: Optional[npt.ArrayLike] = None, return_closest: bool = False
) -> Any: ...
def delaunay(points: npt.ArrayLike) -> npt.NDArray[np.uint32]: ...
def hausdorff(
    VA: Any, FA: Any, VB: Optional[npt.ArrayLike] = None, FB: Optional[npt.ArrayLike] = None, rel_tolerance: float = 1e-6
) -> Tuple[float, float]: ...
def evaluate(reference: MeshLike, prediction: MeshLike) -> dict[str, Any]: ...
def view(
    crust: Union[str, os.PathLike[str]],
    input: Optional[Union[str, os.PathLike[str]]] = None,
    report: Optional[Union[str, os.PathLike[str]]] = None,
    sites: Optional[Union[str, os.PathLike[str]]] = None,
    out: Optional[Union[str, os.PathLike[str]]] = None,
    cells: Optional[Union[str, os.PathLike[str]]] = None,
    check_samples: int = 200000,
) -> Path: ...
