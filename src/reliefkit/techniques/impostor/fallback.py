"""An octahedral impostor as one textured quad: what a glTF viewer that knows nothing of
reliefkit shows.

The quad shows the frame nearest the start view (the view `reliefkit render` draws without
``--view``, `scene.views.DEFAULT_VIEW`) as that frame saw the object: it lies in the frame's
plane through the bounding sphere's centre, spans the sphere's square in the frame's
(right, up) axes (the frame without its padding, which lies outside the sphere) and is
textured with that part of the frame, dilated, alpha-tested at the impostor's 0.5. Seen along
the frame's direction it is the frame, texel for texel; the start view lies within half a
grid cell of it. Double-sided: from behind, its outline is the mirror image of the
object's, as an orthographic outline is.
"""

from __future__ import annotations

import numpy as np

from ...bake.project import dilate
from ...scene.mesh import Material, RenderMesh
from ...scene.views import DEFAULT_VIEW, framing_bounds, orbit_bounds
from . import octahedral

#: The impostor's coverage test (shaders/impostor.glsl): blended coverage below it is empty.
ALPHA_CUTOFF = 0.5

#: (s, t) of the quad's corners, counter-clockwise seen from the frame's direction.
_CORNERS = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)


def start_direction(rep) -> np.ndarray:
    """Unit direction from the impostor's centre towards the eye of the start view."""
    azimuth, elevation, distance = DEFAULT_VIEW
    eye = np.asarray(orbit_bounds(framing_bounds(rep), azimuth, elevation, distance).eye)
    towards = eye - rep.center
    return towards / np.linalg.norm(towards)


def nearest_frame(rep, direction) -> tuple[int, int]:
    """(i, j) of the frame whose direction is nearest ``direction`` (the first of equals)."""
    cosines = octahedral.frame_directions(rep.grid, rep.hemi) @ np.asarray(direction)
    j, i = np.unravel_index(int(np.argmax(cosines)), cosines.shape)
    return int(i), int(j)


def frame_texture(rep, i: int, j: int) -> np.ndarray:
    """Frame (i, j)'s colour without its padding, (F - 2 padding)^2 x 4 uint8 sRGB, row 0 at
    the frame's bottom, its colour dilated into the texels it does not cover."""
    inner = slice(rep.padding, rep.frame - rep.padding)
    cell = rep.color[j * rep.frame:(j + 1) * rep.frame, i * rep.frame:(i + 1) * rep.frame]
    rgba = cell[inner, inner]
    (rgb,) = dilate(rgba[..., 3] > 0, rgba[..., :3])
    return np.concatenate([rgb, rgba[..., 3:]], axis=-1)


def fallback_mesh(rep) -> RenderMesh:
    """The quad of the frame nearest the start view (two triangles, a fixed count)."""
    i, j = nearest_frame(rep, start_direction(rep))
    direction = octahedral.frame_directions(rep.grid, rep.hemi)[j, i]
    right, up = octahedral.frame_basis(direction)
    st = 2.0 * _CORNERS - 1.0
    corners = rep.radius * (st[:, :1] * right + st[:, 1:] * up)
    material = Material(name=f"impostor frame {i}, {j}", texture=frame_texture(rep, i, j),
                        alpha_mode="MASK", alpha_cutoff=ALPHA_CUTOFF, double_sided=True)
    return RenderMesh(corners, [[0, 1, 2], [0, 2, 3]], np.tile(direction, (4, 1)),
                      np.broadcast_to(np.ones(4, np.float32), (4, 4)), uvs=_CORNERS,
                      name=f"{rep.params.get('source') or 'impostor'} frame quad",
                      materials=(material,), origin=rep.center)
