"""`DepthObject` and `VisualHull`: six depth images on a cube, drawn as the intersection of
their displaced volumes (§4) or of their silhouettes' extrusions (§5).

A visual hull is the same images with every depth inside a silhouette set to 0 (the paper's
"all depth values greater than 0 were set to 1", in our convention where depth is measured
from the face); its colours and normals are kept for texturing. Opposite silhouettes of a
cube are mirror images, so a hull needs only three of its six images to be tested.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...bake.project import axis_frame
from ...errors import UsageError
from ...scene.mesh import RenderMesh
from ...scene.views import source_box
from . import depth_object_fallback
from .depth_images import FACE_INDEX, DepthImages, visual_hull

#: `DepthObject.bake_report` warns when more of one image's silhouette than this is carved
#: away by the other images (`reference.carved_fraction`).
CARVED_WARNING = 0.05


@dataclass(eq=False)
class DepthObject:
    """An image-based depth object: `images` (six depth images, see `depth_images`), and the
    bounds of the mesh they were baked from (`source_bounds`, None if unknown): views frame
    the object by them, as they frame its mesh, not by the padded cube or `bounds`."""

    images: DepthImages
    params: dict = field(default_factory=dict)
    source_bounds: np.ndarray | None = None

    #: Whether only silhouettes are stored (depth 0 inside every mask).
    hull = False

    def __post_init__(self) -> None:
        if not isinstance(self.images, DepthImages):
            raise UsageError(f"a depth object needs DepthImages, got "
                             f"{type(self.images).__name__}")
        self.source_bounds = source_box(self.source_bounds)

    @property
    def resolution(self) -> int:
        return self.images.resolution

    @property
    def cube_bounds(self) -> np.ndarray:
        """(2, 3) world box of the cube."""
        c = self.images.cube_to_world
        lo = c[:3, 3]
        return np.array([lo, lo + np.diag(c)[:3]])

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) world box of the object: per axis, the texels that the silhouettes of the
        four images across that axis cover, grown by half a texel (a silhouette misses at
        most that much, where no texel centre is covered); the cube's if no image sees
        anything."""
        n = self.resolution
        lo, hi = np.ones(3), np.zeros(3)
        for face, k in FACE_INDEX.items():
            mask = self.images.mask[k]
            if not mask.any():
                continue
            frame = axis_frame(face)  # rows u, v, h in cube axes
            corner = 0.5 - 0.5 * frame.sum(axis=0)
            rows, cols = np.nonzero(mask)
            for along, index in ((frame[0], cols), (frame[1], rows)):
                a = int(np.argmax(np.abs(along)))
                ends = corner[a] + along[a] * np.array([index.min(), index.max() + 1]) / n
                lo[a], hi[a] = min(lo[a], ends.min()), max(hi[a], ends.max())
        if (lo >= hi).any():
            return self.cube_bounds
        lo, hi = np.maximum(lo - 0.5 / n, 0.0), np.minimum(hi + 0.5 / n, 1.0)
        cube = self.images.cube_to_world
        return np.array([cube[:3, 3] + lo * cube[0, 0], cube[:3, 3] + hi * cube[0, 0]])

    @property
    def tested_faces(self) -> tuple[int, ...]:
        """The images a fragment is tested against: all six, or for a hull one per axis."""
        return (0, 2, 4) if self.hull else tuple(range(6))

    def fallback_mesh(self, triangles: int = 20_000) -> RenderMesh:
        """What a glTF viewer that knows nothing of reliefkit shows: the carved volume (a
        hull's silhouettes' intersection) as a closed mesh of at most ``triangles``
        triangles, by marching cubes on the grid that fits, with vertex colours and normals
        from the images as the renderer textures a point seen straight on
        (`depth_object_fallback`)."""
        return depth_object_fallback.fallback_mesh(self, triangles)

    def bake_report(self) -> list[str]:
        from .reference import carved_fraction  # numba: slow to import

        n = self.resolution
        covered = [f"{100 * float(m.mean()):.0f}%" for m in self.images.mask]
        kind = "visual hull" if self.hull else "depth object"
        lines = [f"{kind}: six {n}x{n} depth images on a cube of side "
                 f"{self.images.side:.4g} (texel {self.images.texel:.3g}); silhouette cover "
                 f"per face (+x -x +y -y +z -z): {' '.join(covered)}"]
        carved = carved_fraction(self.images)
        worst = int(np.argmax(carved))
        if carved[worst] > CARVED_WARNING:
            names = ("+x", "-x", "+y", "-y", "+z", "-z")
            lines.append(f"warning: {carved[worst]:.0%} of what the {names[worst]} image sees "
                         "is carved away by the other images: open or paper-thin parts (a "
                         "ground plane, a sheet) seen edge-on cannot be part of a depth "
                         "object; bake a closed mesh, or the flat part as a relief texture")
        return lines


@dataclass(eq=False)
class VisualHull(DepthObject):
    """The visual hull of six silhouettes (§5): build it with `VisualHull.of(images)`."""

    hull = True

    def __post_init__(self) -> None:
        super().__post_init__()
        images = self.images
        if (images.depth[images.mask] != 0).any():
            raise UsageError("a visual hull's images must have depth 0 inside every "
                             "silhouette (build it with VisualHull.of(images))")

    @classmethod
    def of(cls, images: DepthImages, params: dict | None = None,
           source_bounds: np.ndarray | None = None) -> VisualHull:
        return cls(visual_hull(images), dict(params or {}), source_bounds)
