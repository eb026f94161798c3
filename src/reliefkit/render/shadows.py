"""Shadow maps of the directional light: its orthographic camera over a box, and the
depth pass a drawable renders from it (`shaders/include/shadow_map.glsl` reads it back).
"""

from __future__ import annotations

import numpy as np

from ..core.transforms import translation
from ..scene.camera import Camera

SHADOW_SIZE = 1024
SHADOW_UNIT = 9  # texture unit of u_shadow_map (a drawable's own textures stay below it)


def light_camera(bounds, light, size: int = SHADOW_SIZE):
    """An orthographic camera looking along the light over ``bounds`` (its shadow map)."""
    lo, hi = np.asarray(bounds, np.float64)
    centre, radius = 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo)) or 1.0
    towards = np.asarray(light.direction, np.float64)
    towards = towards / np.linalg.norm(towards)
    up = (1.0, 0.0, 0.0) if abs(towards[1]) > 0.99 else (0.0, 1.0, 0.0)
    return Camera(eye=tuple(centre + 2.0 * radius * towards), target=tuple(centre), up=up,
                  size=(size, size), near=0.5 * radius, far=3.5 * radius, ortho_height=radius)


def render_shadow_map(ctx, bounds, light, origin, draw_depth, size: int = SHADOW_SIZE):
    """Draw ``draw_depth(light_camera)`` into a depth texture from the light; returns the
    texture (the caller releases it) and the uniforms of shadow_map.glsl for geometry
    stored relative to ``origin`` (float64 world point). Leaves the framebuffer and the
    enabled state to the caller to restore."""
    import moderngl

    cam = light_camera(bounds, light, size)
    depth = ctx.depth_texture(cam.size)
    fbo = ctx.framebuffer(depth_attachment=depth)
    try:
        fbo.use()
        fbo.viewport = (0, 0, *cam.size)
        fbo.clear(depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST)  # both faces cast: open meshes and leaves too
        draw_depth(cam)
    except BaseException:
        depth.release()
        raise
    finally:
        fbo.release()
    depth.compare_func = "<="  # sampler2DShadow: each lookup is a depth test, filtered
    depth.filter = (moderngl.LINEAR, moderngl.LINEAR)
    depth.repeat_x = depth.repeat_y = False
    world_texel = 2.0 * cam.ortho_height / size
    light_matrix = np.asarray(cam.proj) @ np.asarray(cam.view) @ translation(
        np.asarray(origin, np.float64))
    return depth, {"u_light_matrix": light_matrix, "u_shadow_map": SHADOW_UNIT,
                   "u_shadow_texel": float(world_texel),
                   "u_shadow_bias": float(world_texel / (cam.far - cam.near))}
