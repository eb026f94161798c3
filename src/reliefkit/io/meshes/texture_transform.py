"""glTF's KHR_texture_transform on base-colour textures, which trimesh parses but drops.

The transform belongs to a material's texture reference in the JSON, and trimesh does not
say which glTF material a geometry came from; so primitives are matched to trimesh's
geometries in order (trimesh makes one per triangle, line or point primitive, in file
order), checked by vertex count, and a file whose order cannot be matched is refused.
"""

from __future__ import annotations

import numpy as np

from .badfile import BadFile
from .gltf import json_tree

EXTENSION = "KHR_texture_transform"
_MODES_TRIMESH_KEEPS = (0, 1, 4, 5)  # points, lines, triangles, triangle strips
_FLIP_V = np.array([[1.0, 0, 0], [0, -1.0, 1.0], [0, 0, 1.0]])  # glTF v runs down, ours up


def uv_transforms(data: bytes, file_type: str, scene) -> dict[str, np.ndarray]:
    """Geometry name -> 3x3 transform of our UVs, for geometries whose material has one."""
    tree = json_tree(data, file_type)  # trimesh parsed it: meshes and materials are lists
    used = tree.get("extensionsUsed")
    if not isinstance(used, list) or EXTENSION not in used:
        return {}
    per_material = [_material_transform(m) for m in tree.get("materials", [])]
    primitives = [p for mesh in tree.get("meshes", []) for p in mesh.get("primitives", [])
                  if p.get("mode", 4) in _MODES_TRIMESH_KEEPS]
    names = list(scene.geometry)
    counts = [_vertex_count(tree, p) for p in primitives]
    if counts != [len(scene.geometry[n].vertices) for n in names]:
        raise BadFile(f"uses {EXTENSION} in a mesh layout that cannot be matched to its "
                      "materials; re-export it with the transform baked into the UVs")
    out = {}
    for name, primitive in zip(names, primitives, strict=True):
        material = primitive.get("material")
        if isinstance(material, int) and 0 <= material < len(per_material) \
                and per_material[material] is not None:
            out[name] = per_material[material]
    return out


def _vertex_count(tree: dict, primitive: dict) -> int | None:
    try:
        return int(tree["accessors"][primitive["attributes"]["POSITION"]]["count"])
    except (KeyError, IndexError, TypeError, ValueError):
        return None


def _material_transform(material) -> np.ndarray | None:
    """The base-colour texture's transform in our UV convention (v up), or None.

    The rotation matrix is [[cos, sin], [-sin, cos]] on glTF's UVs (v down), as three.js,
    Babylon.js and Blender apply it and as Khronos' TextureTransformTest sample expects; the
    GLSL listing of the extension's specification has the opposite sign, which turns the
    texture the wrong way in glTF's UV space (KhronosGroup/glTF#1563).
    """
    try:
        info = material["pbrMetallicRoughness"]["baseColorTexture"]["extensions"][EXTENSION]
        offset = np.asarray(info.get("offset", (0.0, 0.0)), dtype=np.float64).reshape(2)
        rotation = float(info.get("rotation", 0.0))
        scale = np.asarray(info.get("scale", (1.0, 1.0)), dtype=np.float64).reshape(2)
    except (KeyError, TypeError, ValueError, AttributeError):
        return None
    if not (np.isfinite(offset).all() and np.isfinite(rotation) and np.isfinite(scale).all()):
        raise BadFile(f"its {EXTENSION} has NaN or Inf values")
    c, s = np.cos(rotation), np.sin(rotation)
    gltf = (np.array([[1, 0, offset[0]], [0, 1, offset[1]], [0, 0, 1]])
            @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
            @ np.diag([scale[0], scale[1], 1.0]))  # translation * rotation * scale
    return _FLIP_V @ gltf @ _FLIP_V
