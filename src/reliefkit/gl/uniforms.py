"""Setting uniforms: matrices column-major, unused names skipped, the camera's set in one go."""

from __future__ import annotations

import numpy as np


def set_uniforms(prog, values: dict) -> None:
    """Set the uniforms a program actually uses (the compiler drops unused ones)."""
    for name, value in values.items():
        if name not in prog:
            continue
        if isinstance(value, np.ndarray) and value.shape == (4, 4):
            prog[name].write(value.T.astype(np.float32).tobytes())  # GL is column-major
        else:
            prog[name].value = value


def camera_uniforms(camera) -> dict:
    """The uniforms of shaders/include/camera.glsl for any camera."""
    view_dir = np.asarray(camera.eye) - np.asarray(camera.target)
    view_dir = view_dir / np.linalg.norm(view_dir)
    view_proj = np.asarray(camera.proj) @ np.asarray(camera.view)
    return {"u_view": camera.view, "u_proj": camera.proj,
            "u_inv_view_proj": np.linalg.inv(view_proj),
            "u_eye": tuple(float(x) for x in camera.eye), "u_orthographic": camera.orthographic,
            "u_view_dir": tuple(float(x) for x in view_dir),
            "u_viewport": tuple(float(x) for x in camera.size)}
