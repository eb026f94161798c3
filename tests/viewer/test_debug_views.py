"""The page's debug views in headless Chromium against `reliefkit render`'s AOVs, mapped as
docs/viewer.md says in numpy: normals, depth, the iteration heat map (with render's
iterations_mean and iterations_max), the mask difference against the mesh (as
metrics.error_image colours it); a panel that cannot show one says why."""

from __future__ import annotations

from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import numpy as np
import pytest
from browser import canvas_rgba, open_page, served, state
from helpers import sample

from reliefkit import save
from reliefkit.io.inputs import load_input
from reliefkit.metrics import error_image, heat_ramp
from reliefkit.render import render
from reliefkit.scene.light import DEFAULT_LIGHT_ANGLES, DirectionalLight
from reliefkit.scene.views import framing_bounds, orbit_bounds, parse_view
from reliefkit.viewer.site import load_inputs, site_files

SIZE = (128, 128)
VIEW = "30,25"
MESH = "demo:vehicle"


@pytest.fixture(scope="module")
def relief(tmp_path_factory):
    path = tmp_path_factory.mktemp("inputs") / "relief.rk"
    save(path, sample("relief", "relief"))
    return str(path)


@pytest.fixture(scope="module")
def both(gl, browser, relief):
    """A page of the relief texture and the mesh, opened on the normals (the URL), the
    frames render makes of both from its camera, and that camera."""
    specs = [relief, MESH]
    boxes = np.array([framing_bounds(load_input(s)) for s in specs])
    union = np.stack([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])
    camera = orbit_bounds(union, *parse_view(VIEW), SIZE)
    light = DirectionalLight.from_angles(*DEFAULT_LIGHT_ANGLES)
    frames = [render(load_input(s), camera, light=light) for s in specs]
    counted = render(load_input(relief), camera, light=light, count_iterations=True)
    with served(site_files(load_inputs(specs))) as (base, log):
        page = open_page(browser, f"{base}?view={VIEW}&size={SIZE[0]}x{SIZE[1]}&debug=normals")
        yield {"page": page, "opened": state(page), "frames": frames, "counted": counted,
               "camera": camera,
               "radius": float(np.linalg.norm(union[1] - union[0]) / 2), "log": log}
        page.close()


def show(page, mode: str) -> None:
    """Pick ``mode`` in the page's selector and wait for the frame drawn with it; the URL
    follows."""
    frames = state(page)["frames"]
    if state(page)["debug"]["mode"] == mode:
        return
    page.select_option("#debug-views select", mode)
    page.wait_for_function(f"window.reliefkit.frames > {frames}")
    assert state(page)["debug"]["mode"] == mode
    query = parse_qs(urlsplit(page.url).query)
    assert query.get("debug") == (None if mode == "picture" else [mode])


def agreement(page: np.ndarray, covered: np.ndarray, rgb: np.ndarray) -> tuple[float, float]:
    """Coverage IoU of the page's alpha and ``covered``, and the share of pixels both cover
    whose channels are within 4/255 of ``rgb`` (display colours in [0, 1])."""
    seen = page[..., 3] > 0
    iou = (seen & covered).sum() / max((seen | covered).sum(), 1)
    want = np.round(np.clip(rgb, 0, 1) * 255).astype(int)
    diff = np.abs(page[..., :3].astype(int) - want).max(-1)[seen & covered]
    return float(iou), float((diff <= 4).mean())


def test_normals(both):
    page = both["page"]
    assert both["opened"]["debug"]["mode"] == "normals" and both["opened"]["errors"] == []
    show(page, "normals")
    for index, frame in enumerate(both["frames"]):
        iou, within = agreement(canvas_rgba(page, index), frame.mask, frame.normal * 0.5 + 0.5)
        print(f"normals, panel {index}: IoU {iou:.4f}, {within:.2%} within 4/255")
        assert iou >= 0.99 and within >= 0.99


def test_depth(both):
    """The view distance, white at the near side of the framed bounding sphere, black at its
    far side."""
    page, camera, radius = both["page"], both["camera"], both["radius"]
    show(page, "depth")
    eye = np.asarray(camera.eye)
    center = np.linalg.norm(eye - np.asarray(camera.target))
    near, far = center - radius, center + radius
    for index, frame in enumerate(both["frames"]):
        distance = np.linalg.norm(np.nan_to_num(frame.position) - eye, axis=-1)
        grey = np.clip((far - distance) / (far - near), 0, 1)[..., None].repeat(3, -1)
        iou, within = agreement(canvas_rgba(page, index), frame.mask, grey)
        print(f"depth, panel {index}: IoU {iou:.4f}, {within:.2%} within 4/255")
        assert iou >= 0.99 and within >= 0.99


def test_iterations(both):
    """The relief's counts on the heat ramp, 0 to the frame's max; the mesh has none."""
    page, counted = both["page"], both["counted"]
    show(page, "iterations")
    counts = counted.extra["iterations"]
    ran = np.isfinite(counts)
    top = counted.stats["iterations_max"]
    iou, within = agreement(canvas_rgba(page, 0), ran, heat_ramp(np.nan_to_num(counts) / top))
    seen = state(page)["debug"]
    print(f"iterations: IoU {iou:.4f}, {within:.2%} within 4/255; page {seen['iterations'][0]}, "
          f"render {counted.stats}")
    assert iou >= 0.99 and within >= 0.99
    got = seen["iterations"][0]
    assert got["max"] == top
    assert got["mean"] == pytest.approx(counted.stats["iterations_mean"], rel=0.01)
    assert seen["notes"][0] == (f"iterations: mean {got['mean']:.2f}, max {top} "
                                f"(heat ramp 0..{top})")
    assert seen["notes"][1] == "no iteration counts for mesh"
    assert page.locator("figure .note").nth(1).inner_text() == "no iteration counts for mesh"


def test_mask(both):
    page, (relief, mesh) = both["page"], both["frames"]
    show(page, "mask")
    got = canvas_rgba(page, 0)
    want = np.round(error_image(relief, mesh, "mask") * 255).astype(int)
    same = (np.abs(got[..., :3].astype(int) - want).max(-1) <= 4).mean()
    print(f"mask: {same:.2%} of pixels as error_image colours them")
    assert same >= 0.99 and (got[..., 3] == 255).all()
    assert (got[..., 0] > 0).any() and (got[..., 2] > 0).any()  # both differences are seen
    assert state(page)["errors"] == [] and both["log"] == []
    show(page, "picture")  # and back
    for index, frame in enumerate(both["frames"]):
        want = frame.rgba8()
        iou, within = agreement(canvas_rgba(page, index), want[..., 3] > 0, want[..., :3] / 255)
        assert iou >= 0.99 and within >= 0.99


def test_mask_without_a_mesh_says_so(gl, browser, relief):
    with served(site_files(load_inputs([relief]))) as (base, _):
        page = open_page(browser, f"{base}?size=128x128&debug=mask")
        note = page.locator("figure .note").inner_text()
    name = Path(relief).name  # a static site names a file without its folders
    assert note == f"mask difference needs the mesh as another input: reliefkit view {name} MESH"
