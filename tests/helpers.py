"""Fixtures and builders shared by several test modules (test modules never import each other)."""

from __future__ import annotations

import contextlib

import numpy as np

from reliefkit.scene.mesh import RenderMesh, vertex_normals
from reliefkit.techniques.relief.bake import heightfield_normals
from reliefkit.techniques.relief.representation import ReliefTexture

# box [-1, 1] x [0, 1] x [-1, 1]: u along +x, v along -z, h along +y
BOX = np.array([[2.0, 0, 0, -1], [0, 0, 1.0, 0], [0, -2.0, 0, 1], [0, 0, 0, 1]])


def make_relief(height, box_to_world=BOX, safety=None, rgb=(0.2, 0.6, 0.3)):
    height = np.asarray(height, np.float32)
    color = np.zeros(height.shape + (4,), np.uint8)
    color[..., :3] = np.round(np.array(rgb) * 255)
    color[..., 3] = 255
    if safety is None:
        safety = np.ones(height.shape, np.uint8)
    return ReliefTexture(height=height, color=color,
                         normal=heightfield_normals(height, box_to_world),
                         box_to_world=box_to_world, safety=safety)


def terrain_block(n=40):
    """A closed terrain block over [-1, 1]^2: a smooth top, four skirts down to y = 0 and a
    bottom, coloured by x (red), height (green) and z (blue): what a relief texture holds."""
    x, z = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n))
    y = 0.35 + 0.15 * np.sin(2.5 * x) * np.cos(1.5 * z) + 0.1 * x * z
    top = np.stack([x, y, z], -1).reshape(-1, 3)
    bottom = top * [1, 0, 1]
    positions = np.concatenate([top, bottom])
    a = (np.arange(n - 1)[:, None] * n + np.arange(n - 1)).ravel()
    faces = [np.stack([a, a + n, a + n + 1], 1), np.stack([a, a + n + 1, a + 1], 1)]
    ring = np.r_[np.arange(n), np.arange(2 * n - 1, n * n, n),  # the top's border, once around
                 np.arange(n * n - 2, n * n - n - 1, -1), np.arange(n * n - 2 * n, 0, -n)]
    r0, r1 = ring, np.roll(ring, -1)
    faces += [np.stack([r0, r1, r1 + n * n], 1), np.stack([r0, r1 + n * n, r0 + n * n], 1)]
    corners = np.array([0, n - 1, n * n - 1, n * n - n]) + n * n
    faces += [corners[[0, 2, 1]][None], corners[[0, 3, 2]][None]]
    faces = np.concatenate(faces)
    rgb = np.stack([0.2 + 0.3 * (positions[:, 0] + 1), 0.1 + 1.2 * positions[:, 1],
                    0.2 + 0.3 * (positions[:, 2] + 1)], -1)
    colors = np.c_[np.clip(rgb, 0, 1), np.ones(len(positions))].astype(np.float32)
    return RenderMesh(positions, faces, vertex_normals(positions, faces), colors, name="block")


@contextlib.contextmanager
def toy_technique():
    """Plug the toy technique (tests/toy_technique) in for the duration of a test."""
    import toy_technique

    from reliefkit.core.technique import register, unregister

    register(toy_technique.TECHNIQUE)
    try:
        yield toy_technique
    finally:
        unregister(toy_technique.TECHNIQUE.name)


def technique_samples() -> list[tuple[str, str]]:
    """(technique, kind) of every sample representation: the built-ins and the toy's."""
    import toy_technique

    from reliefkit.core.technique import techniques

    out = []
    for tech in (*techniques(), toy_technique.TECHNIQUE):
        assert tech.samples is not None, f"technique {tech.name} declares no samples"
        out += [(tech.name, kind) for kind in tech.samples()]
    return out


def sample_ids(samples) -> list[str]:
    """``technique:kind`` test ids of `technique_samples`' pairs."""
    return [f"{tech}:{kind}" for tech, kind in samples]


def sample(technique_name: str, kind: str):
    import toy_technique

    from reliefkit.core.technique import techniques

    table = {t.name: t for t in (*techniques(), toy_technique.TECHNIQUE)}
    return table[technique_name].samples()[kind]


def shoelace(xy: np.ndarray) -> float:
    """Signed area of a polygon (counter-clockwise positive)."""
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def inside_polygon(xy: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Even-odd rule, one horizontal ray per point: an independent inside test."""
    inside = np.zeros(len(points), bool)
    for a, b in zip(xy, np.roll(xy, -1, axis=0), strict=True):
        crosses = (a[1] > points[:, 1]) != (b[1] > points[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            x = a[0] + (points[:, 1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        inside ^= crosses & (points[:, 0] < x)
    return inside


def triangles_covering(triangles: np.ndarray, points: np.ndarray) -> np.ndarray:
    """How many of the (F, 3, 2) triangles contain each point (strictly, by edge signs)."""
    def side(a, b):
        return (b[:, None, 0] - a[:, None, 0]) * (points[None, :, 1] - a[:, None, 1]) - (
            b[:, None, 1] - a[:, None, 1]) * (points[None, :, 0] - a[:, None, 0])

    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    d1, d2, d3 = side(a, b), side(b, c), side(c, a)
    inside = ((d1 > 0) & (d2 > 0) & (d3 > 0)) | ((d1 < 0) & (d2 < 0) & (d3 < 0))
    return inside.sum(axis=0)


def write_obj_quad(folder, mtl_text: str, material: str, positions, uvs, name: str = "q"):
    """An OBJ of two triangles over four corners using ``material`` of an .mtl beside it."""
    (folder / f"{name}.mtl").write_text(mtl_text)
    (folder / f"{name}.obj").write_text(
        f"mtllib {name}.mtl\n" + "".join(f"v {x:g} {y:g} {z:g}\n" for x, y, z in positions)
        + "".join(f"vt {u:g} {v:g}\n" for u, v in uvs)
        + f"usemtl {material}\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")
    return folder / f"{name}.obj"


def run_cli(*args, cwd=None, env=None, **kw):
    """``reliefkit ARGS`` in a fresh interpreter (stdout, stderr and the exit status); ``env``
    adds to the environment, other keywords go to `subprocess.run`."""
    import os
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "reliefkit.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=300, cwd=cwd,
                          env=None if env is None else {**os.environ, **env}, **kw)


def assert_one_line_error(result, *words, code=None):
    """The command failed with one ``error:`` line on stderr that holds every word."""
    assert result.returncode != 0
    assert code is None or result.returncode == code, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert "Traceback" not in result.stderr
    for word in words:
        assert word in lines[0], lines[0]


def assert_same_frames(got, expected) -> None:
    """Two Frames bit-identical in every field: images, matrices and extra arrays (NaN where
    both are, dtypes alike), stats and warnings."""
    from dataclasses import fields

    for field in fields(got):
        x, y = getattr(got, field.name), getattr(expected, field.name)
        if isinstance(x, dict) and field.name == "extra":
            assert x.keys() == y.keys(), field.name
            for key in x:
                np.testing.assert_array_equal(x[key], y[key], err_msg=f"extra[{key}]",
                                              strict=True)
        elif isinstance(x, dict | list):
            assert x == y, field.name
        else:
            np.testing.assert_array_equal(x, y, err_msg=field.name, strict=True)


def frame_of_plans(gl, rep, drawable, plans, camera, light):
    """The frame ``drawable`` draws of ``rep`` when its plans are ``plans`` (read back from
    JSON, say), through a Scene on the test context."""
    from reliefkit.render.draw import Scene

    drawable.plans = plans
    with Scene(rep, ctx=gl) as scene:
        scene.drawables = [drawable]
        scene.executor.upload(plans)
        return scene.frame(camera, light)


#: The three views the glTF fallbacks are held to (mask IoU against the source mesh).
FALLBACK_VIEWS = ((30.0, 20.0), (150.0, -10.0), (270.0, 60.0))


def fallback_ious(mesh, fallback, size: int = 128) -> list[float]:
    """Mask IoU of ``fallback`` (any drawable) against ``mesh`` from `FALLBACK_VIEWS`."""
    from reliefkit.metrics import mask_iou
    from reliefkit.render import render
    from reliefkit.scene.views import orbit_bounds

    cameras = [orbit_bounds(mesh.bounds, az, el, size=(size, size))
               for az, el in FALLBACK_VIEWS]
    return [mask_iou(render(fallback, c), render(mesh, c)) for c in cameras]


def write_tetrahedron(path, scale: float = 1.0, name_texture: str | None = None):
    """A small OBJ tetrahedron (its x extent ``scale``) at ``path``, its folders made; with
    ``name_texture`` it uses a material whose .mtl (beside it) names that texture."""
    from pathlib import Path

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    head = ""
    if name_texture is not None:
        path.with_suffix(".mtl").write_text(f"newmtl m\nKd 1 1 1\nmap_Kd {name_texture}\n")
        head = f"mtllib {path.with_suffix('.mtl').name}\nusemtl m\n"
    path.write_text(head + f"v 0 0 0\nv {scale:g} 0 0\nv 0 1 0\nv 0 0 1\n"
                    "vt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
                    "f 1/1 3/3 2/2\nf 1/1 2/2 4/4\nf 1/1 4/4 3/3\nf 2/2 3/3 4/4\n")
    return path


MESH_ARRAYS = ("positions", "origin", "indices", "normals", "colors", "uvs", "material")


def assert_same_mesh(mesh, reference) -> None:
    """The same arrays bit for bit (dtype too), materials and name."""
    for name in MESH_ARRAYS:
        got, want = getattr(mesh, name), getattr(reference, name)
        if want is None:
            assert got is None, name
            continue
        assert got is not None and got.dtype == want.dtype, name
        assert got.shape == want.shape and got.tobytes() == want.tobytes(), name
    assert mesh.name == reference.name and len(mesh.materials) == len(reference.materials)
    for m, n in zip(mesh.materials, reference.materials, strict=True):
        assert m == n and m.color.tobytes() == n.color.tobytes()


def write_png(path, rgb=(200, 40, 40)):
    """A 4x4 PNG of one colour at ``path``, its folders made."""
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.full((4, 4, 3), rgb, np.uint8)).save(path)


def write_gltf_triangle(folder):
    """``folder``/m.gltf (its folders made): one textured triangle whose buffer (data.bin)
    and image (images/base colour.png, URL-encoded in the file) are files beside it."""
    import json

    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], "<f4")
    uvs = np.array([[0, 0], [1, 0], [0, 1]], "<f4")
    blob = positions.tobytes() + uvs.tobytes()
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "data.bin").write_bytes(blob)
    write_png(folder / "images" / "base colour.png")
    tree = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                    "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}], "images": [{"uri": "images/base%20colour.png"}],
        "buffers": [{"uri": "data.bin", "byteLength": len(blob)}],
        "bufferViews": [{"buffer": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}]}
    path = folder / "m.gltf"
    path.write_text(json.dumps(tree))
    return path
