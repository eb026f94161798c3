"""Setting uniforms: matrices column-major, unused names skipped, the camera's set in one go."""

from __future__ import annotations

import numpy as np

from ..core.transforms import invert_box, translation


def set_uniforms(prog, values: dict) -> None:
    """Set the uniforms a program actually uses (the compiler drops unused ones, and may
    shorten an array to the entries used: a list value is cut to the array's length)."""
    for name, value in values.items():
        if name not in prog:
            continue
        if isinstance(value, list):
            length = prog[name].array_length
            value = value[:length] if length > 1 else value[0]
        if isinstance(value, np.ndarray) and value.shape == (4, 4):
            with np.errstate(under="ignore"):  # entries like 1e-49 (rounding) become 0
                matrix = value.T.astype(np.float32)
            prog[name].write(matrix.tobytes())  # GL is column-major
        else:
            prog[name].value = value


def camera_uniforms(camera) -> dict:
    """The uniforms of shaders/include/camera.glsl for any camera.

    Shaders see world space relative to ``camera.origin`` (camera-relative rendering): the
    matrices are composed in float64 with the translation to it, so a mesh 1e8 units from
    the world origin keeps the float32 precision it has at the origin. Drawables upload
    their geometry relative to an origin of their own and add `model_offset` to it.
    """
    origin = np.asarray(camera.origin, dtype=np.float64)
    view = np.asarray(camera.view) @ translation(origin)
    view_dir = np.asarray(camera.eye) - np.asarray(camera.target)
    view_dir = view_dir / np.linalg.norm(view_dir)
    return {"u_view": view, "u_proj": camera.proj,
            "u_inv_view_proj": np.linalg.inv(np.asarray(camera.proj) @ view),
            "u_eye": tuple(float(x) for x in np.asarray(camera.eye) - origin),
            "u_orthographic": camera.orthographic,
            "u_view_dir": tuple(float(x) for x in view_dir),
            "u_viewport": tuple(float(x) for x in camera.size)}


def model_offset(camera, origin) -> dict:
    """``u_model_offset``: what a drawable adds to geometry stored relative to ``origin``
    (float64 world point) to place it in the camera's relative world space."""
    offset = np.asarray(origin, dtype=np.float64) - np.asarray(camera.origin, dtype=np.float64)
    return {"u_model_offset": tuple(float(x) for x in offset)}


def box_uniforms(camera, box_to_world) -> dict:
    """``u_box_to_world`` and ``u_world_to_box`` of a box in the camera's relative world
    space (`camera_uniforms`), composed and inverted in float64 about the box."""
    relative = translation(-np.asarray(camera.origin, np.float64)) @ np.asarray(
        box_to_world, np.float64)
    return {"u_box_to_world": relative, "u_world_to_box": invert_box(relative)}
