"""`BillboardBoxes`: a displacement-mapped billboard cloud (Mantler, Jeschke, Wimmer §3).

Every rectangle of a billboard cloud, grown by +-epsilon along its normal, is a *billboard
box*; inside it the volumetric displacement function f_uv(w) says what is there. Box
coordinates are (u, v, w) in [0, 1]^3: u, v along the rectangle's sides, w = 0 at -epsilon
and 1 at +epsilon (the side its faces face). Voxel (i, j, k) is the cell
[i/W, (i+1)/W] x [j/H, (j+1)/H] x [k/D, (k+1)/D]; every lookup is nearest (piecewise
constant), so each variant's occupied set is a union of cells (volumetric) or of per-texel
intervals in w (shell, thick shell), which the exact march intersects exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core.transforms import MAX_COORDINATE, transform_points, unit_cube_corners
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from ...scene.views import source_box
from ...units import format_bytes
from .representation import BillboardCloud

VARIANTS = ("volumetric", "shell", "thick-shell")
MAX_DISTANCE = 255  # distance texels hold whole voxels up to this, clamped


@dataclass(eq=False)
class BillboardBox:
    """One box: where it is, and its displacement function in one of the variants.

    Attributes
    ----------
    box_to_world : (4, 4) float64 affine map of (u, v, w) to world.
    color : sRGB base colour with alpha = occupancy (>= 128: occupied): (D, H, W, 4) uint8
        per voxel for ``volumetric``, (H, W, 4) per texel for the shells.
    normal : world unit normals (n + 1) / 2 * 255, uint8, color's shape with 3 channels.
    displacement : None (volumetric); (H, W, 1) uint16 w * 65535 of the surface (shell, its
        interval is w +- thickness / 2); (H, W, 2) uint16 lowest and highest w (thick shell,
        the interval between them). Texels whose colour alpha is below 128 are empty.
    distance : (D, H, W) uint8 Euclidean distance, in voxels, from each voxel centre to the
        nearest occupied voxel (0 inside one), clamped at `MAX_DISTANCE`: sphere tracing's
        safe step (§3.4.1). D is the box's voxel count along w (voxels about cubic).
    """

    box_to_world: np.ndarray
    color: np.ndarray
    normal: np.ndarray
    distance: np.ndarray
    displacement: np.ndarray | None = None

    @property
    def resolution(self) -> tuple[int, int, int]:
        """(W, H, D) voxels."""
        d, h, w = self.distance.shape
        return w, h, d


@dataclass(eq=False)
class BillboardBoxes:
    """The boxes of one variant, the flat billboard cloud of the same planes (drawn beyond
    the switch distance, §3.4.2), and the thickness of a shell (in w, 0..1).

    Attributes
    ----------
    variant : one of `VARIANTS`.
    boxes : one `BillboardBox` per rectangle of ``cloud``, in its order.
    cloud : the `BillboardCloud` with the same planes and epsilon.
    thickness : the shell's interval width in w (None for the other variants).
    source_bounds, params : as for every representation.
    """

    variant: str
    boxes: list[BillboardBox]
    cloud: BillboardCloud
    thickness: float | None = None
    source_bounds: np.ndarray | None = None
    params: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.variant not in VARIANTS:
            raise UsageError(f"variant must be one of {', '.join(VARIANTS)}, got "
                             f"{self.variant!r}")
        if not isinstance(self.cloud, BillboardCloud):
            raise UsageError("cloud must be a BillboardCloud")
        if len(self.boxes) != self.cloud.count:
            raise UsageError(f"{len(self.boxes)} boxes for the cloud's {self.cloud.count} "
                             "rectangles")
        for k, box in enumerate(self.boxes):
            _check_box(box, self.variant, f"box {k}")
        if self.variant == "shell":
            self.thickness = shell_thickness(self.thickness, "a shell's thickness")
        elif self.thickness is not None:
            raise UsageError(f"only shells have a thickness, not a {self.variant}")
        if not any((b.color[..., 3] >= 128).any() for b in self.boxes):
            raise UsageError("every box is empty: nothing visible to render")
        self.source_bounds = source_box(self.source_bounds)

    @property
    def epsilon(self) -> float:
        return self.cloud.epsilon

    @property
    def bounds(self) -> np.ndarray:
        """World bounding box of every box."""
        points = np.concatenate([transform_points(b.box_to_world, unit_cube_corners())
                                 for b in self.boxes])
        return np.stack([points.min(axis=0), points.max(axis=0)])

    @property
    def center(self) -> np.ndarray:
        return self.bounds.mean(axis=0)

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: the quads of ``cloud``,
        the billboard cloud the boxes hand over to with distance
        (`BillboardCloud.fallback_mesh`: 2 triangles per box, a fixed count)."""
        return self.cloud.fallback_mesh(triangles)

    def fallback_normal_maps(self) -> dict:
        """The normal maps of ``cloud``'s fallback, per material."""
        return self.cloud.fallback_normal_maps()

    def memory_bytes(self) -> dict:
        """Bytes per map as in the paper's Table 2: colour, normals, distance textures (and
        the displacements of the shells); the flat cloud's atlases separately."""
        total = {"color": 0, "normal": 0, "distance": 0, "displacement": 0}
        for box in self.boxes:
            total["color"] += int(box.color.nbytes)
            total["normal"] += int(box.normal.nbytes)
            total["distance"] += int(box.distance.nbytes)
            if box.displacement is not None:
                total["displacement"] += int(box.displacement.nbytes)
        total["billboard_cloud"] = sum(self.cloud.memory_bytes().values())
        return total

    def bake_report(self) -> list[str]:
        """What `reliefkit bake` says of fresh boxes: their variant and memory (Table 2)."""
        memory = self.memory_bytes()
        maps = ", ".join(f"{name} {format_bytes(memory[name])}"
                         for name in ("color", "normal", "distance", "displacement")
                         if memory[name])
        across = sorted({b.resolution[2] for b in self.boxes})
        thickness = f", thickness {self.thickness:.3g}" if self.thickness is not None else ""
        return [f"dmbbc {self.variant}: {len(self.boxes)} boxes, {'/'.join(map(str, across))} "
                f"voxels across{thickness}; {maps}"] + self.cloud.bake_report()

    def summary(self) -> dict:
        lo, hi = self.bounds
        return {"kind": "dmbbc", "variant": self.variant, "boxes": len(self.boxes),
                "voxels": [list(b.resolution) for b in self.boxes],
                "thickness": self.thickness, "epsilon": self.epsilon,
                "bounds_min": lo.tolist(), "bounds_max": hi.tolist(),
                "bytes": self.memory_bytes(), "params": self.params}


def shell_thickness(value, what: str = "thickness") -> float:
    """``value`` as a shell's thickness: a real number (not a string or a bool) in (0, 1],
    a fraction of the box depth."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.number) \
            or not 0 < float(value) <= 1:
        raise UsageError(f"{what} must be a number in (0, 1] (a fraction of the box depth), "
                         f"got {value!r}")
    return float(value)


def _check_box(box: BillboardBox, variant: str, where: str) -> None:
    """Shapes and dtypes of one box against its variant (the .rk reader relies on it)."""
    m = np.asarray(box.box_to_world, dtype=np.float64)
    if m.shape != (4, 4) or not np.isfinite(m).all() or not np.array_equal(m[3], [0, 0, 0, 1]) \
            or (np.abs(m) > MAX_COORDINATE).any():
        raise UsageError(f"{where}: box_to_world must be a finite affine 4x4 matrix")
    with np.errstate(all="ignore"):
        cond = np.linalg.cond(m[:3, :3])
    if not np.isfinite(cond) or cond > 1e12:
        raise UsageError(f"{where}: box_to_world is singular or badly conditioned")
    box.box_to_world = m
    box.distance = np.ascontiguousarray(box.distance)
    if box.distance.dtype != np.uint8 or box.distance.ndim != 3 or 0 in box.distance.shape:
        raise UsageError(f"{where}: distance must be a (D, H, W) uint8 array")
    d, h, w = box.distance.shape
    spatial = (d, h, w) if variant == "volumetric" else (h, w)
    box.color = np.ascontiguousarray(box.color)
    box.normal = np.ascontiguousarray(box.normal)
    if box.color.dtype != np.uint8 or box.color.shape != spatial + (4,):
        raise UsageError(f"{where}: a {variant} box needs color {spatial + (4,)} uint8, got "
                         f"{box.color.dtype} {box.color.shape}")
    if box.normal.dtype != np.uint8 or box.normal.shape != spatial + (3,):
        raise UsageError(f"{where}: a {variant} box needs normal {spatial + (3,)} uint8, got "
                         f"{box.normal.dtype} {box.normal.shape}")
    layers = {"volumetric": None, "shell": 1, "thick-shell": 2}[variant]
    if layers is None:
        if box.displacement is not None:
            raise UsageError(f"{where}: a volumetric box has no displacement map")
        return
    disp = None if box.displacement is None else np.ascontiguousarray(box.displacement)
    if disp is None or disp.dtype != np.uint16 or disp.shape != (h, w, layers):
        raise UsageError(f"{where}: a {variant} box needs displacement ({h}, {w}, {layers}) "
                         "uint16")
    if layers == 2 and (disp[..., 0] > disp[..., 1]).any():
        raise UsageError(f"{where}: a thick shell's lowest w exceeds its highest")
    box.displacement = disp
