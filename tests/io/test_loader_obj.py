"""OBJ files as other tools write them: Windows texture paths, concave polygons.

Every file is written by hand in tmp_path; references are the files' own data (the polygon
the face lists, the image the .mtl names).
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from helpers import inside_polygon, shoelace, triangles_covering
from PIL import Image

from reliefkit.io.meshes import load_mesh

# ------------------------------------------------------------------------- texture paths

RED = (200, 10, 10, 255)
TRIANGLE_OBJ = ("mtllib {mtl}\nusemtl wall\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                "vt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n")


def textured_obj(folder, map_kd: str, image_at: str, mtl_name="m.mtl", mtllib=None):
    """An OBJ whose .mtl says `map_Kd <map_kd>`, with the image stored at `image_at`."""
    image = folder / image_at
    image.parent.mkdir(parents=True, exist_ok=True)
    Image.new("RGBA", (4, 4), RED).convert("RGB" if image.suffix == ".jpg" else "RGBA").save(image)
    (folder / mtl_name).write_text(f"newmtl wall\nKd 1 1 1\nmap_Kd {map_kd}\n")
    path = folder / "model.obj"
    path.write_text(TRIANGLE_OBJ.format(mtl=mtllib or mtl_name))
    return path


WINDOWS_PATHS = {
    "dot_backslash": (".\\wal67ar_small.jpg", "wal67ar_small.jpg"),
    "subfolder_backslash": ("textures\\a.png", "textures/a.png"),
    "subfolder_other_case": ("Textures\\A.PNG", "textures/a.png"),
    "file_other_case": ("WALL.png", "wall.PNG"),
    "absolute_windows_path": ("C:\\Users\\me\\My Models\\wall.png", "wall.png"),
    "file_beside_not_in_subfolder": ("maps\\wall.png", "wall.png"),
}


@pytest.mark.parametrize("case", WINDOWS_PATHS)
def test_texture_paths_from_windows_resolve(tmp_path, case):
    map_kd, stored = WINDOWS_PATHS[case]
    mesh_out = load_mesh(textured_obj(tmp_path, map_kd, stored))
    assert mesh_out.textured
    texture = mesh_out.materials[0].texture
    np.testing.assert_allclose(texture.reshape(-1, 4), np.tile(RED, (16, 1)), atol=8)  # JPEG


def test_mtllib_with_another_case_resolves(tmp_path):
    mesh_out = load_mesh(textured_obj(tmp_path, "wall.png", "wall.png", mtl_name="model.mtl",
                                      mtllib="MODEL.MTL"))
    assert mesh_out.textured


def test_a_path_that_leaves_the_folder_is_not_read(tmp_path):
    folder = tmp_path / "model"
    folder.mkdir()
    Image.new("RGBA", (4, 4), RED).save(tmp_path / "wall.png")
    mesh_out = load_mesh(textured_obj(folder, "..\\wall.png", "unused.png"))
    assert not mesh_out.textured  # the red image beside the folder is not read
    np.testing.assert_allclose(mesh_out.materials[0].color, [1, 1, 1, 1])  # Kd 1 1 1
    (line,) = mesh_out.extra["warnings"]
    assert line.startswith("texture '..\\wall.png' is outside the mesh's folder"), line


def test_a_missing_texture_is_named_as_written(tmp_path):
    mesh_out = load_mesh(textured_obj(tmp_path, "textures\\gone.png", "textures/other.png"))
    assert not mesh_out.textured
    (line,) = mesh_out.extra["warnings"]
    assert line.startswith("texture 'textures\\gone.png' not found"), line


# --------------------------------------------------------------------- concave polygons


def keyhole_xy(n_arc: int = 20) -> np.ndarray:
    """A keyhole outline, counter-clockwise: a unit circle above a slot 0.6 wide."""
    angles = np.linspace(np.radians(-72.5), np.radians(252.5), n_arc)
    return np.vstack([np.column_stack([np.cos(angles), np.sin(angles)]),
                      [[-0.3, -2.0], [0.3, -2.0]]])


def obj_polygon(xy: np.ndarray, with_uvs: bool = False) -> str:
    lines = [f"v {x:.9f} {y:.9f} 0" for x, y in xy]
    if with_uvs:
        lines += [f"vt {x:.9f} {y:.9f}" for x, y in xy]
        corners = [f"{i}/{i}" for i in range(1, len(xy) + 1)]
    else:
        corners = [str(i) for i in range(1, len(xy) + 1)]
    return "\n".join([*lines, "f " + " ".join(corners)]) + "\n"


def assert_covers_exactly(mesh_out, xy: np.ndarray) -> None:
    triangles = mesh_out.positions[mesh_out.indices][..., :2].astype(np.float64)
    e1, e2 = triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
    signed = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    area = shoelace(xy)
    assert signed.min() >= -1e-9, "a triangle is flipped"
    np.testing.assert_allclose(signed.sum(), area, rtol=1e-5)
    points = np.random.default_rng(0).uniform(xy.min(axis=0), xy.max(axis=0), (3000, 2))
    np.testing.assert_array_equal(triangles_covering(triangles, points),
                                  inside_polygon(xy, points).astype(int))


def test_polygon_with_a_hole_cut_open_leaves_the_hole_empty(tmp_path):
    """A square with a square hole joined by a zero-width cut: a fan fills the hole."""
    xy = np.array([[0, 0], [4, 0], [4, 4], [0, 4], [0, 0], [1, 1], [1, 3], [3, 3], [3, 1],
                   [1, 1]], float)
    path = tmp_path / "framed.obj"
    path.write_text(obj_polygon(xy))
    mesh_out = load_mesh(path)
    assert_covers_exactly(mesh_out, xy)


def test_keyhole_polygon_is_covered_exactly_once(tmp_path):
    xy = keyhole_xy()
    path = tmp_path / "keyhole.obj"
    path.write_text(obj_polygon(xy))
    mesh_out = load_mesh(path)
    assert mesh_out.triangle_count == len(xy) - 2
    assert_covers_exactly(mesh_out, xy)
    assert (mesh_out.normals[:, 2] > 0.99).all()  # every triangle faces the polygon's way


def test_polygon_keeps_its_texture_coordinates(tmp_path):
    xy = keyhole_xy(9)
    path = tmp_path / "keyhole_uv.obj"
    path.write_text(obj_polygon(xy, with_uvs=True))
    mesh_out = load_mesh(path)
    assert_covers_exactly(mesh_out, xy)
    np.testing.assert_allclose(mesh_out.uvs, mesh_out.positions[:, :2], atol=1e-6)


@pytest.mark.parametrize("start", range(4))
def test_concave_quad_is_split_along_its_inner_diagonal(tmp_path, start):
    dart = np.roll(np.array([[0, 0], [2, 1], [0, 2], [0.6, 1.0]]), start, axis=0)
    path = tmp_path / "dart.obj"
    path.write_text(obj_polygon(dart))
    mesh_out = load_mesh(path)
    assert mesh_out.triangle_count == 2
    assert_covers_exactly(mesh_out, dart)


def test_convex_faces_and_relative_indices_stay_as_trimesh_splits_them(tmp_path):
    path = tmp_path / "convex.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                    "f 1 2 3 4\nf -4 -2 -1 -5\nf 1 2 3\n")  # convex; relative indices
    expected = trimesh.load_mesh(path, process=False)
    mesh_out = load_mesh(path)
    np.testing.assert_array_equal(mesh_out.indices, expected.faces)


@pytest.mark.parametrize("faces, what", [("f 1/1/1 2/2/2 3/3/3", "texture coordinates"),
                                         ("f 1//1 2//2 3//3", "normals")])
def test_references_to_undefined_uvs_or_normals_are_dropped_with_a_warning(tmp_path, faces,
                                                                           what):
    """Such files exist (exporters that write v/vt/vn without the vt or vn records); common
    importers read them, so the triangle is kept and the references ignored."""
    path = tmp_path / "t.obj"
    normals = "vn 0 0 1\n" * 3 if what == "texture coordinates" else ""
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n" + normals + faces + "\n")
    mesh = load_mesh(path)
    assert mesh.triangle_count == 1
    assert len(mesh.extra["warnings"]) == 1 and what in mesh.extra["warnings"][0]


def test_backslash_continues_a_line(tmp_path):
    path = tmp_path / "c.obj"
    path.write_bytes(b"v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\nf 1 2 \\\r\n 3 4\r\n")
    mesh = load_mesh(path)
    assert mesh.triangle_count == 2 and "warnings" not in mesh.extra
