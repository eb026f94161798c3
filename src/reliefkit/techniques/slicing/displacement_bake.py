"""The ``displacement`` baker (``reliefkit bake MESH|HEIGHTMAP --as displacement``).

Three sources of a displacement map:

* a HEIGHTMAP (2D array): one polygon, a 2 x 2 square in the xz plane centred on the origin
  with y up (u along +x, v along +z, so an image's top row lies at -z seen from above, as
  for relief textures), the heights as the displacement (kept if already in [0, 1], else
  rescaled), coloured with a terrain palette;
* a MESH without ``--displacement``: the mesh projected from above (y) onto ONE polygon, the
  bottom face of its bounding box, with `reliefkit.bake.project.project_mesh` (its top-down
  colour and height image, like a relief bake); the scale is the box's height;
* a MESH with ``--displacement NAME|FILE``: the mesh (with uvs) is the base, extruded along
  its vertex normals, with a procedural texture (`displacement_textures.TEXTURES`, tiled
  and wrapped) or a heightmap file (.png/.npy, clamped unless tiled).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...bake.detail import LAYER_PER_EDGE, TILE_PER_LAYER, layer_thickness, uv_tiling
from ...bake.project import axis_frame, dilate, project_mesh
from ...bake.uv_atlas import kept_atlas
from ...colorspace import srgb_decode
from ...core.params import param
from ...errors import FormatError, UsageError
from ...io.npy import npy_header
from ...scene.heightmap import check_file, is_heightmap, load_heightmap
from ...scene.mesh import RenderMesh
from .displacement import DisplacementMap
from .displacement_textures import (
    TEXTURES,
    make_texture,
    normalised_heights,
    terrain_colors,
)

#: Without --displacement-scale: a heightmap's square rises by this much of its diagonal (a
#: mesh base by `reliefkit.bake.detail.layer_thickness`: a skin following its detail, as
#: thick as a shell volume's default)
DEFAULT_SCALE = 0.1
SQUARE = 2.0         # side of a heightmap's polygon


@dataclass(frozen=True)
class DisplacementParams:
    displacement_scale: float | None = param(
        None, "world length of height 1 along the normals (none: the box height for a "
        f"projected mesh, {LAYER_PER_EDGE:g} of a mesh base's median edge length, "
        f"{DEFAULT_SCALE:g} of a heightmap square's diagonal)",
        kind="float", lo=1e-12)
    res: int = param(256, "displacement texture resolution (texels per side)", lo=2,
                     hi=8192)
    displacement: str | None = param(
        None, "the displacement texture on a mesh base (" + ", ".join(TEXTURES) + ", or a "
        "heightmap .png/.npy); none: project the mesh from above onto one polygon",
        kind="str")
    tile: tuple | None = param(None, "how many times the texture repeats over the uvs, U,V "
                               "(none: a procedural texture on a mesh base as often as makes "
                               f"a tile about {TILE_PER_LAYER:g} scales long on the surface, "
                               "a file once)",
                               kind="floats", count=2, lo=1, hi=4096)


def square_base(name: str = "square"):
    """One polygon (two triangles): a SQUARE x SQUARE square in the xz plane, y up, uvs
    u = (x + 1) / 2, v = (z + 1) / 2."""
    half = SQUARE / 2
    positions = np.array([[-half, 0, -half], [half, 0, -half], [half, 0, half],
                          [-half, 0, half]], np.float64)
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    faces = np.array([[0, 2, 1], [0, 3, 2]])  # counter-clockwise seen from +y
    normals = np.tile((0.0, 1.0, 0.0), (4, 1))
    return RenderMesh(positions, faces, normals, np.ones((4, 4), np.float32), uvs, name=name)


def box_base(box_to_world: np.ndarray, name: str):
    """The bottom face h = 0 of a box (u, v, h) -> world as one polygon, uvs = (u, v)."""
    corners = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
    world = corners @ box_to_world[:3, :2].T + box_to_world[:3, 3]
    up = box_to_world[:3, 2] / np.linalg.norm(box_to_world[:3, 2])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    if np.cross(world[1] - world[0], world[2] - world[0]) @ up < 0:
        faces = faces[:, ::-1].copy()
    return RenderMesh(world, faces, np.tile(up, (4, 1)), np.ones((4, 4), np.float32),
                      corners.astype(np.float32), name=name)


def _diagonal(bounds) -> float:
    lo, hi = np.asarray(bounds, np.float64)
    return float(np.linalg.norm(hi - lo)) or 1.0


def _scale(p: DisplacementParams, fallback: float) -> float:
    return p.displacement_scale if p.displacement_scale is not None else fallback


def _file_texture(spec: str):
    """(colour, height) of a file: the paper's displacement texture (an RGBA .png, or an
    (H, W, 4) .npy of linear floats, with the displacement in alpha) or a grey heightmap
    (.png or a 2D .npy; colours from the terrain palette)."""
    if not is_heightmap(spec):
        raise UsageError(f"--displacement {spec}: not one of {', '.join(TEXTURES)}, nor a "
                         "heightmap or displacement texture (.png or .npy)")
    check_file(spec)  # a FIFO would block the read
    rgba = _rgba_texture(spec)
    if rgba is not None:
        return rgba
    # load_heightmap: row 0 is the image's top row; texture rows run along +v
    height = normalised_heights(load_heightmap(spec))
    return terrain_colors(height), height


def _rgba_texture(spec: str):
    """An RGBA displacement texture's (linear colour with alpha 1, height = alpha), or None
    for a file without an alpha channel (then it is a heightmap)."""
    from pathlib import Path

    path = Path(spec)
    if path.suffix.lower() == ".png":
        from PIL import Image, UnidentifiedImageError

        try:
            with Image.open(path) as image:
                if image.mode not in ("RGBA", "LA", "PA") and not (
                        image.mode == "P" and "transparency" in image.info):
                    return None
                rgba = np.asarray(image.convert("RGBA"), np.float64) / 255.0
        except (OSError, UnidentifiedImageError) as exc:
            raise FormatError(f"{path}: not a readable PNG ({exc})") from None
        color = srgb_decode(rgba[..., :3])
    else:
        try:
            with open(path, "rb") as fh:
                shape, _, dtype = npy_header(fh)
        except (OSError, ValueError) as exc:
            raise FormatError(f"{path}: not a readable .npy array ({exc})") from None
        if len(shape) != 3:
            return None
        if shape[2] != 4 or dtype.kind != "f" or max(shape[:2]) > 8192:
            raise FormatError(f"{path}: a displacement texture .npy must be (H, W, 4) float "
                              f"RGBA (at most 8192 per side), got {shape} {dtype}")
        try:
            rgba = np.load(path, allow_pickle=False).astype(np.float64)
        except (OSError, ValueError) as exc:  # a body shorter than its header says
            raise FormatError(f"{path}: not a readable .npy array ({exc})") from None
        if not np.isfinite(rgba).all():
            raise FormatError(f"{path}: the texture contains NaN or Inf values")
        color = np.clip(rgba[..., :3], 0.0, 1.0)
    if min(rgba.shape[:2]) < 2:
        raise FormatError(f"{path}: a displacement texture needs at least 2x2 texels")
    height = np.clip(rgba[..., 3], 0.0, 1.0).astype(np.float32)
    color = np.concatenate([color, np.ones((*height.shape, 1))], axis=-1).astype(np.float32)
    return color, height


def bake_displacement(source, p: DisplacementParams, progress=None) -> DisplacementMap:
    tile = (1.0, 1.0) if p.tile is None else tuple(float(t) for t in p.tile)
    if isinstance(source, np.ndarray):
        height = normalised_heights(source)
        base = square_base("heightmap")
        scale = _scale(p, DEFAULT_SCALE * _diagonal(base.bounds))
        return DisplacementMap(base, terrain_colors(height), height, scale, tile,
                               wrap=tile != (1.0, 1.0),
                               params={"source": "heightmap", "texture": "heightmap"})
    if p.displacement is None:
        return _projected(source, p, tile)
    if source.uvs is None:
        raise UsageError(f"{source.name}: --displacement needs a base mesh with texture "
                         "coordinates (uvs); unwrap it, or leave --displacement out to "
                         "project the mesh onto one polygon")
    if p.displacement in TEXTURES:
        color, height = make_texture(p.displacement, p.res)
        wrap = True
    else:
        color, height = _file_texture(p.displacement)
        wrap = tile != (1.0, 1.0)
    scale = _scale(p, layer_thickness(source))
    if p.tile is None and wrap:  # a periodic texture repeats at the mesh's own scale
        tile = tuple(float(t) for t in uv_tiling(source, TILE_PER_LAYER * scale))
    base, dropped = _usable(source)
    surface, left_out = kept_atlas(base)  # the surface's own look, under the texture's colours
    return DisplacementMap(base, color, height, scale, tile, wrap,
                           params={"source": source.name, "texture": p.displacement,
                                   "dropped_triangles": dropped,
                                   "materials_left_out": left_out},
                           source_bounds=source.bounds, surface=surface)


def _usable(mesh):
    """The mesh without triangles that have no area in space or in uv (its materials kept),
    and how many were left out."""
    tris = np.asarray(mesh.indices, np.int64)
    p = mesh.world_positions[tris]
    uv = np.asarray(mesh.uvs, np.float64)[tris]
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    d1, d2 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
    uv_area = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    good = (area > 1e-12 * max(float(area.max()), 1e-300)) & (uv_area > 1e-14)
    if not good.any():
        raise UsageError(f"{mesh.name}: none of its triangles has an area in space and in "
                         "uv; there is nothing to displace")
    if good.all():
        return mesh, 0
    return RenderMesh(mesh.world_positions, tris[good], mesh.normals, mesh.colors, mesh.uvs,
                      name=mesh.name, materials=mesh.materials,
                      material=np.asarray(mesh.material)[good]), int((~good).sum())


def _projected(mesh, p: DisplacementParams, tile) -> DisplacementMap:
    """The mesh seen from above (+y) through its bounding box, onto the box's bottom face."""
    if tile != (1.0, 1.0):
        raise UsageError("--tile needs --displacement (a projected mesh covers its polygon "
                         "once)")
    lo, hi = np.asarray(mesh.bounds, np.float64)
    frame = axis_frame("y")  # rows u, v, h
    size = hi - lo
    pad = 1e-3 * (float(np.linalg.norm(size)) or 1.0)
    lo, hi = lo - pad, hi + pad
    size = hi - lo
    extent = np.abs(frame) @ size                    # world length along u, v, h
    corner = np.zeros(3)  # the corner where u = v = h = 0
    for k in range(3):
        axis = frame[k]
        corner += np.where(axis != 0, np.where(axis > 0, lo, hi), 0.0) * np.abs(axis)
    box = np.eye(4)
    for k in range(3):
        box[:3, k] = frame[k] * extent[k]
    box[:3, 3] = corner
    longest = max(extent[0], extent[1])
    w = max(2, int(round(p.res * extent[0] / longest)))
    h = max(2, int(round(p.res * extent[1] / longest)))
    proj = project_mesh(mesh, box, (w, h))
    color = np.clip(np.asarray(proj.color, np.float32), 0, 1).copy()

    (color_rgb,) = dilate(proj.mask, color[..., :3])
    color[..., :3] = color_rgb
    color[..., 3] = proj.mask  # nothing where the mesh is not: an empty base (displacement.py)
    height = np.clip(proj.height, 0, 1).astype(np.float32)
    base = box_base(box, f"{mesh.name} (projected)")
    scale = p.displacement_scale if p.displacement_scale is not None else float(extent[2])
    # a given scale stretches the projected heights; heights stay the box fractions
    return DisplacementMap(base, color, height, scale, (1.0, 1.0), False,
                           params={"source": mesh.name, "texture": "projection"},
                           source_bounds=mesh.bounds)
