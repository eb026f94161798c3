"""``bake --compress bc`` on any kind, and ``info`` showing each array's GPU format and bytes."""

from __future__ import annotations

from helpers import assert_one_line_error, run_cli

from reliefkit.compact.encodings import encoding_of
from reliefkit.io.rk import load


def test_bake_compress_bc_writes_the_encoded_arrays_and_info_lists_them(tmp_path):
    raw, compact = tmp_path / "raw.rk", tmp_path / "c.rk"
    common = ["bake", "demo:terrain", "--as", "relief", "--depth-res", "32", "--color-res", "32"]
    assert run_cli(*common, "-o", raw).returncode == 0
    out = run_cli(*common, "--compress", "bc", "--color-format", "bc1", "--height-bits", "8",
                  "-o", compact)
    assert out.returncode == 0, out.stderr
    assert "raw -> " in out.stdout and "compact" in out.stdout
    rep = load(compact)
    assert (encoding_of(rep.height).format, encoding_of(rep.color).format,
            encoding_of(rep.normal).format) == ("u8", "bc1", "bc7")
    assert compact.stat().st_size < raw.stat().st_size
    info = run_cli("info", compact)
    assert info.returncode == 0, info.stderr
    lines = {line.split()[0]: line for line in info.stdout.splitlines() if "on the GPU" in line}
    # 32 x 32 texels: BC1 8 bytes per 4x4 block (with its mip chain: 128+32+8+8+8+8 blocks
    # -> 1,528 B), u8 one byte a texel, BC7 16 bytes per block
    assert "float32 32x32  on the GPU u8 1.0 KiB (raw 4.0 KiB)" in lines["height"]
    assert "uint8 32x32x4  on the GPU bc1" in lines["color"]
    assert "float32 32x32x3  on the GPU bc7" in lines["normal"]


def test_encoding_flags_without_compress_are_refused(tmp_path):
    assert_one_line_error(run_cli("bake", "demo:terrain", "--as", "relief", "--height-bits",
                                  "8", "-o", tmp_path / "x.rk"), "--compress bc")


def test_bake_takes_compress_by_its_name_as_documented():
    """``rk.bake(mesh, kind, compress="bc")``: the string its docstring shows."""
    from reliefkit import bake
    from reliefkit.compact.encodings import encoding_of
    from reliefkit.scene.assets import make_asset

    rep = bake(make_asset("blob"), "relief-cube", compress="bc", depth_res=16)
    assert encoding_of(rep.parts[0].color) is not None


def test_compress_that_changes_nothing_says_so(tmp_path):
    """A shell volume without a material (its 3D textures stay raw) compresses nothing:
    the bake warns instead of a silent no-op."""
    result = run_cli("bake", "demo:sphere", "--as", "shell-volume", "--texture", "clouds",
                     "--texture-size", "16,16,8", "--compress", "bc", "-o", tmp_path / "c.rk")
    assert result.returncode == 0
    assert "--compress bc changed nothing" in result.stderr


def test_a_depth_object_compresses_its_colour_and_normals(tmp_path):
    result = run_cli("bake", "demo:cup", "--as", "depth-object", "--res", "16",
                     "--compress", "bc", "-o", tmp_path / "c.rk")
    assert result.returncode == 0 and "changed nothing" not in result.stderr
    lines = {line.split()[0]: line for line in run_cli("info", tmp_path / "c.rk")
             .stdout.splitlines() if line.strip()}
    assert "on the GPU bc7" in lines["color"] and "on the GPU bc7" in lines["normal"]
    assert "on the GPU raw" in lines["depth"]
