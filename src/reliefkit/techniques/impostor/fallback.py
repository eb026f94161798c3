"""An octahedral impostor as one textured quad: what a glTF viewer that knows nothing of
reliefkit shows.

The quad faces the start view (the view `reliefkit render` draws without ``--view``,
`scene.views.DEFAULT_VIEW`) and shows what the impostor itself shows from there: the
impostor drawn by reliefkit from the start view's eye, in a square view that just holds its
bounding sphere, under a flat light (so the texture is base colour and coverage). The quad
is that view's cross-section through the sphere's centre: seen from the start view's eye it
is the impostor's own picture pixel for pixel (a textured plane is a projective map), and
from elsewhere a picture of the object on a card. Its colour is dilated into the texels it
does not cover (a viewer builds its own mip levels) and alpha-tested at the impostor's 0.5.
Double-sided: from behind, its outline is the mirror image of the object's.

A frame of the grid would do without a render, but the nearest frame lies up to half a grid
cell (about 8 degrees at grid 12, more near the octahedron's edges) from the start view, and
an orthographic frame cannot follow the start view's perspective (3.1 radii away, the near
parts look larger): on the vehicle, mask IoU 0.890 against the mesh from the start view,
0.979 so.
"""

from __future__ import annotations

import numpy as np

from ...bake.project import dilate
from ...colorspace import to_rgba8
from ...render.draw import render
from ...scene.camera import Camera
from ...scene.light import DirectionalLight
from ...scene.mesh import Material, RenderMesh
from ...scene.views import DEFAULT_VIEW, framing_bounds, orbit_bounds

#: The impostor's coverage test (shaders/impostor.glsl): blended coverage below it is empty.
ALPHA_CUTOFF = 0.5
#: Colour = base colour: the viewer lights the quad itself.
FLAT = DirectionalLight(intensity=0.0, ambient=1.0, specular=0.0)
#: Texels across the quad per texel across a frame's inside (the blend and parallax resolve
#: a little more than one frame).
OVERSAMPLE = 2

#: (s, t) of the quad's corners, counter-clockwise seen from the start view.
_CORNERS = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float64)


def start_camera(rep) -> tuple[Camera, float]:
    """The start view's eye looking at the bounding sphere's centre in a square view that
    just holds the sphere, at `OVERSAMPLE` times a frame's resolution; and the half size of
    that view's cross-section through the centre (orthographic, the sphere's square, from
    an eye inside the sphere)."""
    azimuth, elevation, distance = DEFAULT_VIEW
    view = orbit_bounds(framing_bounds(rep), azimuth, elevation, distance)
    texels = OVERSAMPLE * max(8, rep.frame - 2 * rep.padding)
    eye = np.asarray(view.eye)
    away = float(np.linalg.norm(eye - rep.center))
    if away <= 1.01 * rep.radius:  # inside the sphere: look from outside, orthographically
        towards = (eye - rep.center) / max(away, 1e-12)
        eye = rep.center + 3.0 * rep.radius * towards
        return Camera(eye=tuple(eye), target=tuple(rep.center), up=view.up,
                      size=(texels, texels), ortho_height=rep.radius, near=rep.radius,
                      far=5.0 * rep.radius), rep.radius
    half_angle = np.arcsin(rep.radius / away)
    camera = Camera(eye=tuple(eye), target=tuple(rep.center), up=view.up,
                    fov_deg=float(np.degrees(2.0 * half_angle)), size=(texels, texels),
                    near=0.5 * (away - rep.radius), far=away + 2.0 * rep.radius)
    return camera, away * float(np.tan(half_angle))


def fallback_mesh(rep) -> RenderMesh:
    """The start view's quad (two triangles, a fixed count)."""
    camera, half = start_camera(rep)
    frame = render(rep, camera, light=FLAT)
    rgba = to_rgba8(frame.color)[::-1]  # the frame's row 0 is its top; a texture's is v = 0
    covered = frame.mask[::-1]
    rgba[..., 3] = np.where(covered, 255, 0)
    (rgb,) = dilate(covered, rgba[..., :3])
    texture = np.concatenate([rgb, rgba[..., 3:]], axis=-1)
    right, up, towards = camera.view[0, :3], camera.view[1, :3], camera.view[2, :3]
    st = 2.0 * _CORNERS - 1.0
    corners = half * (st[:, :1] * right + st[:, 1:] * up)
    material = Material(name="impostor start view", texture=texture, alpha_mode="MASK",
                        alpha_cutoff=ALPHA_CUTOFF, double_sided=True)
    return RenderMesh(corners, [[0, 1, 2], [0, 2, 3]], np.tile(towards, (4, 1)),
                      np.broadcast_to(np.ones(4, np.float32), (4, 4)), uvs=_CORNERS,
                      name=f"{rep.params.get('source') or 'impostor'} start view quad",
                      materials=(material,), origin=rep.center)
