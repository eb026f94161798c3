"""`reliefkit batch --sheet`: each output's thumbnail beside its mesh's, in sheet.png and
index.html; the thumbnails are the mesh and the bake from the default view."""

from __future__ import annotations

import numpy as np
from helpers import write_tetrahedron
from PIL import Image

from reliefkit import cli
from reliefkit.pictures import TILE_BACKGROUND

SIZE = 128


def covered(path) -> np.ndarray:
    """Pixels of a thumbnail that are not the tiles' background."""
    rgb = np.asarray(Image.open(path).convert("RGB")).astype(int)
    background = np.round(np.array([c ** (1 / 2.2) for c in TILE_BACKGROUND]) * 255)
    return np.abs(rgb - background).max(axis=2) > 12


def test_sheet_shows_each_output_beside_its_mesh(tmp_path, capsys):
    library = tmp_path / "lib"
    write_tetrahedron(library / "a.obj")
    write_tetrahedron(library / "sub" / "b.obj", scale=2.0)
    (library / "broken.obj").write_text("v 0 0 0\nv 0 0 0\nf 1 2 1\n")
    out = tmp_path / "out"
    status = cli.main(["batch", str(library), "--as", "relief", "--depth-res", "64", "--out",
                       str(out), "--sheet"])
    assert status == 1  # the broken one
    for stem in ("a", "sub/b"):
        mesh, output = out / "thumbnails" / f"{stem}.mesh.png", out / "thumbnails" / f"{stem}.png"
        assert Image.open(mesh).size == Image.open(output).size == (SIZE, SIZE)
        # the mesh's: exactly the pixels `reliefkit render` covers from the default view
        reference = tmp_path / "render.png"
        assert cli.main(["render", str(library / f"{stem}.obj"), "--size", f"{SIZE}x{SIZE}",
                         "-o", str(reference)]) == 0
        alpha = np.asarray(Image.open(reference))[..., 3] > 0
        assert np.array_equal(covered(mesh), alpha)
        # the relief's: the same silhouette, up to its 64-texel heightfield
        a, b = covered(mesh), covered(output)
        assert (a & b).sum() / (a | b).sum() > 0.9
    sheet = Image.open(out / "sheet.png")
    assert sheet.width > 4 * SIZE and sheet.height > SIZE  # four tiles in a row
    page = (out / "index.html").read_text()
    for link in ('src="thumbnails/a.mesh.png"', 'src="thumbnails/a.png"',
                 'src="thumbnails/sub/b.mesh.png"', 'href="sub/b.rk"'):
        assert link in page
    assert "broken.obj: has no triangle" in page
    capsys.readouterr()
    # a rerun without thumbnails on disk bakes again to make them; with them it skips
    (out / "thumbnails" / "a.png").unlink()
    assert cli.main(["batch", str(library / "a.obj"), "--as", "relief", "--depth-res", "64",
                     "--out", str(out), "--sheet"]) == 0
    assert (out / "thumbnails" / "a.png").is_file()
    assert cli.main(["batch", str(library / "a.obj"), "--as", "relief", "--depth-res", "64",
                     "--out", str(out), "--sheet"]) == 0
    assert "skipped        1" in capsys.readouterr().out
