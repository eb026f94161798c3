"""reliefkit: render geometry from textures with depth.

>>> import reliefkit as rk
>>> mesh = rk.load_mesh("model.glb")
>>> frame = rk.render(mesh, rk.Camera.orbit(mesh.center, 30, 25, 3 * mesh.radius))
"""

from . import metrics
from .bake import bake
from .errors import FormatError, GPUError, MeshError, ReliefkitError, UsageError
from .io.inputs import load_mesh
from .io.rk import load, save
from .render import Frame, render
from .scene.camera import Camera
from .scene.light import DirectionalLight
from .scene.mesh import RenderMesh
from .techniques.billboard import (
    BillboardBoxes,
    BillboardCloud,
    bake_billboard_cloud,
    bake_boxes,
    build_billboard_cloud,
)
from .techniques.relief import (
    ReliefObject,
    ReliefTexture,
    bake_relief,
    bake_relief_cube,
    bake_relief_frustum,
    relief_from_heights,
)
from .techniques.shellvolume import TexturedShell, VolumeTexture, build_shell, visibility_order
from .techniques.slicing import (
    DepthImages,
    DepthObject,
    DisplacementMap,
    VisualHull,
    bake_depth_images,
)

__all__ = [
    "load_mesh", "RenderMesh", "Camera", "DirectionalLight", "render", "Frame", "save", "load",
    "bake", "metrics", "bake_relief", "bake_relief_frustum", "bake_relief_cube",
    "relief_from_heights", "ReliefTexture", "ReliefObject", "build_billboard_cloud",
    "bake_billboard_cloud", "bake_boxes", "BillboardCloud", "BillboardBoxes",
    "build_shell", "visibility_order", "VolumeTexture", "TexturedShell",
    "bake_depth_images", "DepthImages", "DepthObject", "VisualHull", "DisplacementMap",
    "ReliefkitError", "MeshError", "FormatError", "GPUError", "UsageError",
]
__version__ = "0.1.0"
