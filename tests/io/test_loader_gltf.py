"""glTF files the loader must read or refuse in one clear line: Draco, glTF 1.0, extensions.

Nothing a library logs or warns while loading may reach stderr: what matters becomes the
`MeshError`, the rest is silenced.
"""

from __future__ import annotations

import json
import logging
import struct
import subprocess
import sys
import warnings

import numpy as np
import pytest
import trimesh

from reliefkit.errors import MeshError
from reliefkit.io.meshes import load_mesh


def expect_error(path, *words):
    with pytest.raises(MeshError) as info:
        load_mesh(path)
    message = str(info.value)
    assert "\n" not in message and path.name in message
    for word in words:
        assert word.lower() in message.lower(), message
    return message


def glb_json(data: bytes) -> dict:
    (size,) = struct.unpack_from("<I", data, 12)
    return json.loads(data[20:20 + size])


def with_glb_json(data: bytes, tree: dict) -> bytes:
    """The GLB `data` with its JSON chunk replaced by `tree` (padded to 4 bytes)."""
    (size,) = struct.unpack_from("<I", data, 12)
    rest = data[20 + size:]
    text = json.dumps(tree).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text + rest
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def draco_box(tmp_path, suffix=".glb"):
    pytest.importorskip("DracoPy")
    box = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    box.apply_translation((10.0, 0.0, 0.0))
    path = tmp_path / f"draco{suffix}"
    box.export(str(path), extension_draco=True)
    return path, box


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_draco_compressed_gltf_loads(tmp_path, suffix):
    path, box = draco_box(tmp_path, suffix)
    required = (glb_json(path.read_bytes()) if suffix == ".glb"
                else json.loads(path.read_text()))["extensionsRequired"]
    assert required == ["KHR_draco_mesh_compression"]  # the file really is compressed

    mesh_out = load_mesh(path)
    assert mesh_out.triangle_count == len(box.faces)
    written = np.sort(box.vertices[box.faces].reshape(-1, 3), axis=0)
    got = np.sort(mesh_out.positions[mesh_out.indices].reshape(-1, 3), axis=0)
    np.testing.assert_allclose(got, written, atol=1e-3)  # Draco quantizes positions


def load_in_a_fresh_process(path, *, without_draco=False) -> tuple[str, str]:
    """(stdout, stderr) of `load_mesh(path)` in a new interpreter, as a user's command runs it.

    pytest captures log records and warnings itself, so only a process of its own shows what
    would reach a user's terminal.
    """
    script = "\n".join([
        "import sys",
        f"if {without_draco}: sys.modules['DracoPy'] = None  # as if it were not installed",
        "from reliefkit.errors import MeshError",
        "from reliefkit.io.meshes import load_mesh",
        "try:",
        "    print('loaded', load_mesh(sys.argv[1]).triangle_count)",
        "except MeshError as exc:",
        "    print('error:', exc)",
    ])
    done = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True,
                          text=True, timeout=120, check=True)
    return done.stdout.strip(), done.stderr


def test_draco_without_its_decoder_is_one_error(tmp_path):
    path, _ = draco_box(tmp_path)
    out, err = load_in_a_fresh_process(path, without_draco=True)
    assert out.startswith("error:") and "\n" not in out
    assert "Draco" in out and "pip install DracoPy" in out, out
    assert err == ""


def test_draco_loads_quietly(tmp_path):
    path, box = draco_box(tmp_path)
    assert load_in_a_fresh_process(path) == (f"loaded {len(box.faces)}", "")


def test_unknown_required_extension_is_refused(tmp_path):
    data = trimesh.creation.box().export(file_type="glb")
    tree = glb_json(data)
    tree["extensionsUsed"] = tree["extensionsRequired"] = ["EXT_meshopt_compression"]
    path = tmp_path / "meshopt.glb"
    path.write_bytes(with_glb_json(data, tree))
    expect_error(path, "EXT_meshopt_compression", "not supported")


def test_an_extension_that_fails_while_parsing_is_an_error_not_a_warning(tmp_path):
    """Draco declared but not required, and its data broken: trimesh only logs, we refuse."""
    path, _ = draco_box(tmp_path)
    data = path.read_bytes()
    tree = glb_json(data)
    del tree["extensionsRequired"]
    view = tree["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]
    tree["bufferViews"][view["bufferView"]]["byteLength"] = 8  # a cut-off Draco blob
    path.write_bytes(with_glb_json(data, tree))
    expect_error(path, "KHR_draco_mesh_compression")


def test_library_log_records_and_warnings_stay_off_stderr(tmp_path, monkeypatch):
    """What trimesh logs or warns while loading never reaches the caller's handlers."""
    real = trimesh.load_scene

    def noisy(*args, **kwargs):
        logging.getLogger("trimesh").warning("something trimesh finds odd")
        warnings.warn("a library's warning", UserWarning, stacklevel=1)
        return real(*args, **kwargs)

    monkeypatch.setattr(trimesh, "load_scene", noisy)
    seen = []
    handler = logging.Handler()
    handler.emit = seen.append
    logging.getLogger().addHandler(handler)
    path = tmp_path / "box.glb"
    trimesh.creation.box().export(str(path))
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            assert load_mesh(path).triangle_count == 12
    finally:
        logging.getLogger().removeHandler(handler)
    assert seen == [] and caught == []


GLTF1 = {"asset": {"version": "1.0"}, "meshes": {"m": {"primitives": []}},
         "scenes": {"s": {"nodes": []}}, "scene": "s"}


def test_gltf_1_is_named_as_unsupported(tmp_path):
    path = tmp_path / "old.gltf"
    path.write_text(json.dumps(GLTF1))
    message = expect_error(path, "glTF 1.0 is not supported")
    assert "corrupt" not in message


def test_glb_1_is_named_as_unsupported(tmp_path):
    text = json.dumps(GLTF1).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0) + text  # glTF 1.0 binary: JSON chunk type 0
    path = tmp_path / "old.glb"
    path.write_bytes(struct.pack("<4sII", b"glTF", 1, 12 + len(body)) + body)
    message = expect_error(path, "glTF 1.0 is not supported")
    assert "corrupt" not in message
