"""reliefkit: render geometry from textures with depth.

>>> import reliefkit as rk
>>> mesh = rk.load_mesh("model.glb")
>>> frame = rk.render(mesh, rk.Camera.orbit(mesh.center, 30, 25, 3 * mesh.radius))
"""

from __future__ import annotations

import importlib
import sys
import types

# each public name and the module it lives in; imported on first use (PEP 562), so that
# `import reliefkit.cli` is quick and the command line takes Ctrl-C from its first moment.
# The functions that look things up in the registry come from the composition root, which
# registers the built-ins before their first call.
_EXPORTS = {
    "metrics": "",
    **dict.fromkeys(("bake", "load", "render", "save", "export", "batch"), ".builtins"),
    "Frame": ".render", "Camera": ".scene.camera",
    "DirectionalLight": ".scene.light", "load_mesh": ".io.inputs",
    "RenderMesh": ".scene.mesh",
    **dict.fromkeys(("ReliefkitError", "MeshError", "FormatError", "GPUError", "UsageError"),
                    ".errors"),
    **dict.fromkeys(("BillboardBoxes", "BillboardCloud", "bake_billboard_cloud", "bake_boxes",
                     "build_billboard_cloud"), ".techniques.billboard"),
    **dict.fromkeys(("ReliefObject", "ReliefTexture", "bake_relief", "bake_relief_cube",
                     "bake_relief_frustum", "relief_from_heights"), ".techniques.relief"),
    **dict.fromkeys(("TexturedShell", "VolumeTexture", "build_shell", "visibility_order"),
                    ".techniques.shellvolume"),
    **dict.fromkeys(("DepthImages", "DepthObject", "DisplacementMap", "VisualHull",
                     "bake_depth_images"), ".techniques.slicing"),
    **dict.fromkeys(("OctahedralImpostor", "bake_impostor"), ".techniques.impostor"),
}
__all__ = list(_EXPORTS)
__version__ = "0.1.0"


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = importlib.import_module(_EXPORTS[name] or f".{name}", __name__)
    value = module if not _EXPORTS[name] else getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_EXPORTS})


class _Package(types.ModuleType):
    """Importing the packages ``reliefkit.bake`` and ``reliefkit.render`` would set them as
    attributes here; the public names ``bake`` and ``render`` stay the root's functions."""

    def __setattr__(self, name: str, value) -> None:
        if isinstance(value, types.ModuleType) and _EXPORTS.get(name):
            return  # resolved by __getattr__ on first use
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package
