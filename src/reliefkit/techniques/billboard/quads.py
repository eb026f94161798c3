"""A billboard cloud's rectangles as quads: the vertex arrays its renderer draws and its glTF
fallback exports, one copy of where each corner is and which atlas texel it shows.

Light on imports (numpy only), so the representation's own modules may use it.
"""

from __future__ import annotations

import numpy as np

#: (s, t) of a quad's four corners, counter-clockwise seen from the side u x v faces, so
#: gl_FrontFacing is true there; and its two triangles.
_QUAD_ST = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)
_QUAD_TRIANGLES = np.array([0, 1, 2, 0, 2, 3], np.uint32)


def quad_attributes(cloud, origin) -> dict[str, np.ndarray]:
    """The rectangles of a `BillboardCloud` as vertex arrays, (4P, 3) float32 each:
    ``in_position`` the corner relative to ``origin``, ``in_atlas`` (u, v, page),
    ``in_plane_normal``; corner k of rectangle p is row 4p + k.

    The atlas coordinate of (s, t) is ((x + s w) / W, (y + t h) / H): texel (x + i, y + j)
    then holds s = (i + 0.5) / w, t = (j + 0.5) / h, as the representation defines it.
    """
    s, t = _QUAD_ST[:, 0][None, :, None], _QUAD_ST[:, 1][None, :, None]
    corners = cloud.corners[:, None] + s * cloud.u_axes[:, None] + t * cloud.v_axes[:, None]
    relative = corners - np.asarray(origin, dtype=np.float64)
    page, x, y, w, h = (cloud.rects[:, k, None].astype(np.float64) for k in range(5))
    height, width = cloud.color.shape[1:3]
    atlas = np.stack([(x + s[..., 0] * w) / width, (y + t[..., 0] * h) / height,
                      np.broadcast_to(page, (cloud.count, 4))], axis=-1)
    normals = np.broadcast_to(cloud.normals[:, None], (cloud.count, 4, 3))
    return {name: a.reshape(-1, 3).astype(np.float32) for name, a in
            (("in_position", relative), ("in_atlas", atlas), ("in_plane_normal", normals))}


def quad_indices(count: int) -> np.ndarray:
    """Two triangles per quad, indexing `quad_attributes`."""
    return (_QUAD_TRIANGLES[None] + 4 * np.arange(count, dtype=np.uint32)[:, None]).ravel()
