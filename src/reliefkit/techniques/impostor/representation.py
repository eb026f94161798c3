"""`OctahedralImpostor`: an object as a grid of orthographic views on an octahedral map of
directions, each with colour, normal and depth, drawn as one camera-facing quad."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...compact.encodings import encoding_of
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from ...scene.views import source_box
from . import fallback

MIN_FRAME = 8        # texels on a frame's side, padding excluded
MAX_ATLAS = 8192     # texels on the atlas's side (every GL 4 GPU has at least 16384)
MAX_GRID = 64        # frames on the grid's side


def check_grid(grid, hemi: bool) -> int:
    """``grid`` as an int, refused unless the map can blend three distinct frames."""
    if isinstance(grid, bool) or not isinstance(grid, int | np.integer) \
            or not 2 <= grid <= MAX_GRID:
        raise UsageError(f"--grid must be an integer in 2..{MAX_GRID}, got {grid!r}")
    if not hemi and grid < 3:
        raise UsageError("the full octahedral map needs --grid 3 or more (its four corner "
                         "frames are all the view from below); use --hemi for a grid of 2")
    return int(grid)


def frame_size(atlas_res: int, grid: int, padding: int) -> int:
    """Texels on one frame's side for an atlas of ``atlas_res`` (rounded down to a multiple
    of ``grid``); refuses a grid the atlas cannot hold with room for ``padding``."""
    size = atlas_res // grid
    if size - 2 * padding < MIN_FRAME:
        raise UsageError(f"an atlas of {atlas_res} texels holds {grid} x {grid} frames of "
                         f"{size} texels, too few for {padding} texels of padding and "
                         f"{MIN_FRAME} of view: use --atlas-res "
                         f"{grid * (MIN_FRAME + 2 * padding)} or more, or a smaller --grid")
    return size


@dataclass(eq=False)
class OctahedralImpostor:
    """``grid`` x ``grid`` orthographic frames of an object, one per direction of the full or
    hemi octahedral map (`octahedral`), packed into one atlas per channel.

    Frame (i, j) looks along -d, d = `octahedral.frame_directions`[j, i], at the bounding
    sphere (``center``, ``radius``); it covers the square of half side ``frame_radius`` =
    radius * F / (F - 2 ``padding``) around the centre in its (right, up) axes
    (`octahedral.frame_basis`), so ``padding`` texels on every side stay outside the sphere.
    Its F x F texels are atlas columns i F .. (i + 1) F, rows j F .. (j + 1) F (row 0 is
    v = 0, the frame's bottom).

    Attributes
    ----------
    color : (G F, G F, 4) uint8 sRGB base colour (unlit); alpha is the coverage. Empty texels
        hold their nearest covered texel's colour (dilated), alpha 0.
    normal : (G F, G F, 3) uint8 object-space unit normals as (n + 1) / 2 * 255, dilated.
    depth : (G F, G F) uint8: the surface's height along d above the frame's plane through
        the centre, (h / radius + 1) / 2 * 255 (255 in front, 0 at the back), dilated.
    source_bounds : (2, 3) float64 world box of the mesh it was baked from, or None.
    params : the bake's parameters (JSON).
    """

    grid: int
    hemi: bool
    center: np.ndarray
    radius: float
    padding: int
    color: np.ndarray
    normal: np.ndarray
    depth: np.ndarray
    source_bounds: np.ndarray | None = None
    params: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.hemi, bool | np.bool_):
            raise UsageError(f"hemi must be true or false, got {self.hemi!r}")
        self.hemi = bool(self.hemi)
        self.grid = check_grid(self.grid, self.hemi)
        self.center = np.asarray(self.center, dtype=np.float64)
        if self.center.shape != (3,) or not np.isfinite(self.center).all():
            raise UsageError("center must be 3 finite numbers")
        self.radius = float(self.radius)
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise UsageError(f"radius must be a positive finite number, got {self.radius}")
        self.color = _atlas(self.color, "color", 4)
        side = self.color.shape[0]
        if side % self.grid or side > MAX_ATLAS:
            raise UsageError(f"the atlas side ({side}) must be a multiple of the grid "
                             f"({self.grid}) and at most {MAX_ATLAS}")
        if isinstance(self.padding, bool) or not isinstance(self.padding, int | np.integer) \
                or self.padding < 0:
            raise UsageError(f"padding must be an integer >= 0, got {self.padding!r}")
        self.padding = int(self.padding)
        frame_size(side, self.grid, self.padding)
        self.normal = _atlas(self.normal, "normal", 3, side)
        self.depth = _atlas(self.depth, "depth", None, side)
        if not (self.color[..., 3] >= 128).any():
            raise UsageError("every texel of the impostor is empty (alpha below 0.5): "
                             "nothing visible to render")
        self.source_bounds = source_box(self.source_bounds)

    @property
    def frame(self) -> int:
        """Texels on one frame's side."""
        return self.color.shape[0] // self.grid

    @property
    def frame_radius(self) -> float:
        """Half the side of the square a frame covers, world units."""
        return self.radius * self.frame / (self.frame - 2 * self.padding)

    @property
    def bounds(self) -> np.ndarray:
        """The bounding sphere's box, (2, 3) float64 world."""
        return np.stack([self.center - self.radius, self.center + self.radius])

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: one quad facing the start
        view, covering the bounding sphere's square, textured with what the impostor shows
        from there (MASK at 0.5, double-sided); always 2 triangles, whatever ``triangles``
        says (`fallback`)."""
        return fallback.fallback_mesh(self)

    @property
    def nbytes(self) -> int:
        return self.color.nbytes + self.normal.nbytes + self.depth.nbytes

    def bake_report(self) -> list[str]:
        """The grid and the atlases as stored (their bytes are on the ``wrote`` line)."""
        f = self.frame
        stored = ", ".join(f"{what} {_stored_format(array, raw)}" for what, array, raw in (
            ("colour", self.color, "RGBA8"), ("normals", self.normal, "RGB8"),
            ("depth", self.depth, "R8")))
        return [f"octahedral impostor: {self.grid} x {self.grid} frames "
                f"({'hemi' if self.hemi else 'full'} map) of {f} x {f} texels, atlases "
                f"{self.color.shape[0]}²: {stored}"]


def _stored_format(array, raw: str) -> str:
    """The atlas's encoding (``bc7``, after ``--compress bc``) or ``raw``."""
    encoded = encoding_of(array)
    return raw if encoded is None else encoded.format.upper()


def _atlas(array, name: str, channels: int | None, side: int | None = None) -> np.ndarray:
    """A square uint8 atlas of ``channels`` (None: one, no channel axis)."""
    array = np.ascontiguousarray(array)
    shape_ok = array.ndim == (2 if channels is None else 3) and array.shape[0] == array.shape[1] \
        and (channels is None or array.shape[2] == channels) and array.shape[0] > 0 \
        and (side is None or array.shape[0] == side)
    if array.dtype != np.uint8 or not shape_ok:
        want = f"({side or 'S'}, {side or 'S'}{'' if channels is None else f', {channels}'})"
        raise UsageError(f"{name} must be a square {want} uint8 atlas, got {array.dtype} "
                         f"{array.shape}")
    return array
