"""Analytic scenes for the slicing tests: a box, a sphere, a cup (a box with a square hole)."""

from __future__ import annotations

import numpy as np
import trimesh

from reliefkit.scene.camera import Camera, pixel_segments
from reliefkit.scene.mesh import RenderMesh, vertex_normals


def render_mesh(tm, name, rgb=(0.8, 0.5, 0.2)):
    pos = np.asarray(tm.vertices, np.float32)
    faces = np.asarray(tm.faces)
    colors = np.tile([*rgb, 1.0], (len(pos), 1))
    return RenderMesh(pos, faces, vertex_normals(pos, faces), colors, name=name)


BOX_LO = np.array([-0.3, -0.4, 0.0])
BOX_HI = np.array([0.7, 0.2, 0.8])


def box_mesh():
    tm = trimesh.creation.box(extents=BOX_HI - BOX_LO)
    tm.apply_translation((BOX_LO + BOX_HI) / 2)
    return render_mesh(tm, "box")


SPHERE_CENTRE = np.array([0.1, 0.2, -0.3])
SPHERE_RADIUS = 0.7


def sphere_mesh():
    tm = trimesh.creation.icosphere(subdivisions=5, radius=SPHERE_RADIUS)
    tm.apply_translation(SPHERE_CENTRE)
    return render_mesh(tm, "sphere")


#: outer box [-1, 1] x [0, 1] x [-1, 1], hole [-0.5, 0.5] x [0.4, 1] x [-0.5, 0.5]
CUP_FLOOR = 0.4
CUP_TOP = 1.0


def cup_mesh():
    parts = [((-1, 0, -1), (1, CUP_FLOOR, 1)),          # floor slab
             ((-1, CUP_FLOOR, -1), (-0.5, 1, 1)), ((0.5, CUP_FLOOR, -1), (1, 1, 1)),
             ((-0.5, CUP_FLOOR, -1), (0.5, 1, -0.5)), ((-0.5, CUP_FLOOR, 0.5), (0.5, 1, 1))]
    boxes = []
    for lo, hi in parts:
        lo, hi = np.array(lo, float), np.array(hi, float)
        tm = trimesh.creation.box(extents=hi - lo)
        tm.apply_translation((lo + hi) / 2)
        boxes.append(tm)
    return render_mesh(trimesh.util.concatenate(boxes), "cup")


def views(target, distance=3.0, size=(64, 64)):
    return [Camera.orbit(target, az, el, distance, fov_deg=40.0, size=size)
            for az, el in ((30, 20), (-70, 45), (160, -30), (0, 85))]


def rays(camera):
    near, far = pixel_segments(camera)
    return near, far - near


def ray_box(camera, lo, hi):
    """Analytic first hit of every pixel with an axis-aligned box: mask, world points."""
    o, d = rays(camera)
    with np.errstate(divide="ignore", invalid="ignore"):
        s1, s2 = (lo - o) / d, (hi - o) / d
    t0 = np.nanmax(np.minimum(s1, s2), axis=-1)
    t1 = np.nanmin(np.maximum(s1, s2), axis=-1)
    mask = (t0 <= t1) & (t1 >= 0) & (t0 <= 1)
    return mask, np.where(mask[..., None], o + np.maximum(t0, 0)[..., None] * d, np.nan)


def ray_sphere(camera, centre, radius):
    o, d = rays(camera)
    oc = o - centre
    a = (d * d).sum(-1)
    b = (oc * d).sum(-1)
    c = (oc * oc).sum(-1) - radius ** 2
    disc = b * b - a * c
    mask = disc >= 0
    t = (-b - np.sqrt(np.where(mask, disc, 0))) / a
    mask &= (t >= 0) & (t <= 1)
    return mask, np.where(mask[..., None], o + t[..., None] * d, np.nan)


def iou(a, b):
    return (a & b).sum() / max((a | b).sum(), 1)


def box_distance(points, lo, hi):
    """Unsigned distance of points to the surface of the box [lo, hi]."""
    outside = np.linalg.norm(np.maximum(np.maximum(lo - points, points - hi), 0), axis=-1)
    inside = np.minimum(points - lo, hi - points).min(axis=-1)
    return np.where(outside > 0, outside, np.maximum(inside, 0))


def frame_from_json_plans(obj, camera, **options):
    """``obj`` drawn from ``camera`` by plans that went through JSON text and copied arrays
    (`render.plan.to_json`, `from_json`) instead of its drawable's own."""
    import json

    from reliefkit.render.draw import Scene
    from reliefkit.render.plan import from_json, to_json

    with Scene(obj, **options) as scene:
        drawable = scene.drawables[0]
        doc, arrays = to_json(drawable.plans)
        drawable.plans = from_json(json.loads(json.dumps(doc)),
                                   {k: np.array(a) for k, a in arrays.items()})
        scene.executor.upload(drawable.plans)
        return scene.frame(camera)
