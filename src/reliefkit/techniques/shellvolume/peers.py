"""Visibility orders from other libraries, for comparison with `order.visibility_order`.

`vtk_depth_sort`: VTK's ``vtkCellCenterDepthSort`` (the cell-centre depth sort behind VTK's
unstructured-grid volume renderers): it sorts the cells by their centres' depth, i.e. the
same approximation as ``visibility_order(method="centroid")``. VTK is optional (the
``peers`` extra, ``pip install reliefkit[peers]``); without it the peer reports itself
unavailable instead of raising.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

#: VTK's cell type id of a linear tetrahedron.
VTK_TETRA = 10


@dataclass(frozen=True)
class PeerOrder:
    """A peer's front-to-back order of a shell's tetrahedra.

    order : (T,) int32 tetrahedron indices, nearest first (empty when unavailable).
    seconds : wall time of the sort alone (not building the peer's data structures).
    available : whether the peer could run.
    reason : why not (one line), "" when available.
    """

    order: np.ndarray
    seconds: float
    available: bool
    reason: str = ""


def _unavailable(reason: str) -> PeerOrder:
    return PeerOrder(np.empty(0, np.int32), 0.0, False, reason)


def _vtk():
    """The VTK classes used here, or a one-line reason they cannot be imported."""
    try:
        from vtkmodules.util.numpy_support import (
            numpy_to_vtk,
            numpy_to_vtkIdTypeArray,
            vtk_to_numpy,
        )
        from vtkmodules.vtkCommonCore import vtkPoints
        from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkUnstructuredGrid
        from vtkmodules.vtkRenderingCore import vtkCamera, vtkCellCenterDepthSort
    except Exception as error:  # ImportError, or a broken install (missing shared libraries)
        return None, f"vtk unavailable ({type(error).__name__}: {error}); pip install vtk"
    return {"numpy_to_vtk": numpy_to_vtk, "numpy_to_vtkIdTypeArray": numpy_to_vtkIdTypeArray,
            "vtk_to_numpy": vtk_to_numpy,
            "vtkPoints": vtkPoints, "vtkCellArray": vtkCellArray,
            "vtkUnstructuredGrid": vtkUnstructuredGrid, "vtkCamera": vtkCamera,
            "vtkCellCenterDepthSort": vtkCellCenterDepthSort}, ""


def vtk_available() -> tuple[bool, str]:
    """(whether VTK can be imported, the reason when not)."""
    classes, reason = _vtk()
    return classes is not None, reason


def vtk_depth_sort(shell, camera) -> PeerOrder:
    """Front-to-back order of `shell`'s tetrahedra by ``vtkCellCenterDepthSort`` for a
    ``vtkCamera`` matching `camera` (Camera: eye, target, up, vertical field of view, near
    and far; orthographic cameras as a parallel projection of half height
    ``ortho_height``; a MatrixCamera as a parallel projection along its ``view_dir``)."""
    vtk, reason = _vtk()
    if vtk is None:
        return _unavailable(reason)
    grid = _grid(vtk, shell)
    sorter = vtk["vtkCellCenterDepthSort"]()
    sorter.SetInput(grid)
    sorter.SetCamera(_camera(vtk, camera))
    sorter.SetDirectionToFrontToBack()
    sorter.SetMaxCellsReturned(max(1, len(shell.tets)))
    start = time.perf_counter()
    sorter.InitTraversal()
    pieces = []
    while True:
        cells = sorter.GetNextCells()
        if cells is None or cells.GetNumberOfTuples() == 0:
            break
        pieces.append(vtk["vtk_to_numpy"](cells).copy())
    seconds = time.perf_counter() - start
    order = np.concatenate(pieces).astype(np.int32) if pieces else np.empty(0, np.int32)
    return PeerOrder(order, seconds, True, "")


def _grid(vtk, shell):
    """A vtkUnstructuredGrid of the shell's tetrahedra (cell i is tetrahedron i)."""
    points = vtk["vtkPoints"]()
    points.SetData(vtk["numpy_to_vtk"](np.ascontiguousarray(shell.positions, np.float64),
                                       deep=True))
    tets = np.asarray(shell.tets, dtype=np.int64)
    count = len(tets)
    offsets = np.arange(0, 4 * count + 1, 4, dtype=np.int64)
    cells = vtk["vtkCellArray"]()
    to_ids = vtk["numpy_to_vtkIdTypeArray"]
    cells.SetData(to_ids(offsets, deep=True), to_ids(tets.ravel(), deep=True))
    grid = vtk["vtkUnstructuredGrid"]()
    grid.SetPoints(points)
    grid.SetCells(VTK_TETRA, cells)
    return grid


def _camera(vtk, camera):
    """A vtkCamera looking as `camera` does."""
    cam = vtk["vtkCamera"]()
    eye = np.asarray(camera.eye, dtype=np.float64)
    target = np.asarray(camera.target, dtype=np.float64)
    if hasattr(camera, "up"):
        up = np.asarray(camera.up, dtype=np.float64)
    else:  # MatrixCamera: the view matrix's up row
        up = np.asarray(camera.view, dtype=np.float64)[1, :3]
    cam.SetPosition(*eye)
    cam.SetFocalPoint(*target)
    cam.SetViewUp(*up)
    near = float(getattr(camera, "near", 0.0))
    far = float(getattr(camera, "far", 0.0))
    if 0 < near < far:
        cam.SetClippingRange(near, far)
    if camera.orthographic:
        cam.ParallelProjectionOn()
        height = getattr(camera, "ortho_height", None)
        if height:
            cam.SetParallelScale(float(height))
    else:
        cam.ParallelProjectionOff()
        cam.SetViewAngle(float(camera.fov_deg))
    return cam
