"""Shader loader: namespaces, includes with #line, define variants, compile errors naming file
and line, a bounded per-context cache, GLSL ES portability and the wheel's package data
(the shaders and the viewer's page)."""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from helpers import toy_technique

from reliefkit.core.technique import techniques
from reliefkit.errors import GPUError
from reliefkit.gl import shaders
from reliefkit.render.mesh import MESH_PROGRAMS

FILES = {
    "test:prog.glsl": "//! defines: RED GREEN\n#if defined VERTEX_SHADER\nin vec2 p;\n"
                      "void main() { gl_Position = vec4(p, 0.0, 1.0); }\n#endif\n"
                      "#if defined FRAGMENT_SHADER\n#include \"include/col.glsl\"\nout vec4 c;\n"
                      "void main() { c = col(); }\n#endif\n",
    "test:include/col.glsl": "vec4 col() {\n#if defined RED\n  return vec4(1, 0, 0, 1);\n#else\n"
                             "  return vec4(0, 1, 0, 1);\n#endif\n}\n",
    "test:broken.glsl": "#if defined VERTEX_SHADER\nvoid main() { gl_Position = vec4(0.0); }\n"
                        "#endif\n#if defined FRAGMENT_SHADER\n#include \"include/bad.glsl\"\n"
                        "out vec4 c;\nvoid main() { c = bad(); }\n#endif\n",
    "test:include/bad.glsl": "vec4 bad() {\n  return undefined_thing;\n}\n",
    "test:loop.glsl": "#include \"loop.glsl\"\n",
    "test:escape.glsl": "#include \"../../secret.glsl\"\n",
    "test:shared.glsl": "#if defined VERTEX_SHADER\nvoid main() { gl_Position = vec4(0.0); }\n"
                        "#endif\n#if defined FRAGMENT_SHADER\n"
                        "#include \"core:include/shading.glsl\"\nout vec4 c;\n"
                        "void main() { c = vec4(shade_phong(vec3(1.0), vec3(0, 1, 0), "
                        "vec3(0, 1, 0), 1.0), 1.0); }\n#endif\n",
}


@pytest.fixture
def fake_files(monkeypatch):
    real = shaders.read_shader_file

    def read(name):
        if name.startswith("test:"):
            if name not in FILES:
                raise GPUError(f"shader file not found: {name}")
            return FILES[name]
        return real(name)

    monkeypatch.setattr(shaders, "read_shader_file", read)
    namespaces = shaders._namespace_table
    monkeypatch.setattr(shaders, "_namespace_table", lambda: {**namespaces(), "test": "reliefkit"})


def test_stage_sources_have_version_stage_defines_and_line(fake_files):
    src = shaders.stage_sources("test:prog.glsl", {"RED": True})
    assert set(src) == {"vertex_shader", "fragment_shader", "_files"}
    frag = src["fragment_shader"].splitlines()
    assert frag[0] == "#version 330 core"
    assert "#define FRAGMENT_SHADER" in frag and "#define RED" in frag
    assert "#define RK_FRAME_ATTACHMENTS 3" in frag
    assert "#line 100001 1" in frag  # the include is file 1 and starts at its line 1
    assert "#line 8 0" in frag  # back in prog.glsl after the include on line 7
    assert src["_files"] == ["test:prog.glsl", "test:include/col.glsl"]


def test_qualified_names_relative_and_absolute():
    assert shaders.qualify("mesh.glsl") == "core:mesh.glsl"
    assert shaders.qualify("heightfield.glsl", "relief:include/intersect.glsl") == \
        "relief:include/heightfield.glsl"
    assert shaders.qualify("core:include/camera.glsl", "relief:relief.glsl") == \
        "core:include/camera.glsl"
    with pytest.raises(GPUError, match="leaves its namespace"):
        shaders.qualify("../x.glsl", "relief:relief.glsl")


def test_include_across_namespaces_compiles(gl, fake_files):
    assert "core:include/shading.glsl" in shaders.stage_sources("test:shared.glsl")["_files"]
    shaders.program(gl, "test:shared.glsl")


def test_bad_names_are_errors(fake_files):
    with pytest.raises(GPUError, match="unknown define.*BLUE.*known: COUNT_ITERATIONS, GREEN, RED"):
        shaders.stage_sources("test:prog.glsl", {"BLUE": True})
    with pytest.raises(GPUError, match="nested deeper"):
        shaders.stage_sources("test:loop.glsl")
    with pytest.raises(GPUError, match="leaves its namespace"):
        shaders.stage_sources("test:escape.glsl")
    with pytest.raises(GPUError, match="unknown shader namespace 'nowhere'"):
        shaders.read_shader_file("nowhere:x.glsl")
    with pytest.raises(GPUError, match="not found: core:missing.glsl"):
        shaders.read_shader_file("core:missing.glsl")


def test_namespaces_follow_the_registered_techniques():
    """A technique's namespace is its name, found while it is registered and not after."""
    with toy_technique():
        assert "void main" in shaders.read_shader_file("toy:toy.glsl")
    with pytest.raises(GPUError, match="unknown shader namespace 'toy'"):
        shaders.read_shader_file("toy:toy.glsl")


def test_variants_compile_and_differ(gl, fake_files):
    red = shaders.program(gl, "test:prog.glsl", {"RED": True})
    green = shaders.program(gl, "test:prog.glsl", {})
    assert red is not green
    assert shaders.program(gl, "test:prog.glsl", {"RED": True}) is red  # cached


def test_compile_error_names_the_included_file_and_line(gl, fake_files):
    with pytest.raises(GPUError, match=r"test:include/bad\.glsl:2: .*undefined_thing"):
        shaders.program(gl, "test:broken.glsl")


def test_cache_is_bounded(gl, fake_files, monkeypatch):
    monkeypatch.setattr(shaders, "CACHE_SIZE", 2)
    first = shaders.program(gl, "test:prog.glsl", {"RED": True})
    shaders.program(gl, "test:prog.glsl", {"RED": True, "GREEN": True})
    shaders.program(gl, "test:prog.glsl", {"GREEN": True})
    cache = gl.extra["reliefkit_programs"]
    assert len(cache) == 2 and first not in cache.values()


TWO_CONTEXTS = """
from reliefkit.gl import shaders
from reliefkit.gl.context import create_context
a, b = create_context(), create_context()
pa = shaders.program(a, "mesh.glsl")
pb = shaders.program(b, "mesh.glsl")
assert pa is not pb and pa.ctx is a and pb.ctx is b, "contexts share a program"
assert shaders.program(a, "mesh.glsl") is pa
print("ok")
"""


def test_cache_never_confuses_two_contexts(gl):
    # in a child process: a second context would change which one is current in this one
    out = subprocess.run([sys.executable, "-c", TWO_CONTEXTS], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr[-2000:]


def draw_path_programs():
    variants = list(MESH_PROGRAMS)
    for tech in techniques():
        variants += tech.programs
    return variants


def test_every_technique_declares_its_draw_path_programs():
    files = {v.file for v in draw_path_programs()}
    for tech in techniques():
        assert any(f.startswith(tech.name + ":") for f in files), tech.name


@pytest.mark.parametrize("es", [False, True], ids=["glsl330", "es300"])
def test_every_draw_path_program_compiles(gl, es):
    """The browser viewer (WebGL2) runs the same files: GL 4.3 accepts GLSL ES 3.00."""
    for variant in draw_path_programs():
        try:
            shaders.program(gl, variant.file, variant.defines, es=es)
        except GPUError as exc:
            pytest.fail(f"{variant.file} {variant.defines} as {'ES' if es else 'core'}: {exc}")


def test_wheel_contains_every_shader_and_the_viewer_page(tmp_path):
    root = Path(__file__).resolve().parents[2]
    package = root / "src" / "reliefkit"
    shaders = {str(p.relative_to(package.parent)) for p in package.rglob("*.glsl")}
    page = {f"reliefkit/viewer/static/{name}" for name in ("index.html", "viewer.js")}
    assert len(shaders) >= 8
    # from a copy: a build/ folder left in the checkout would ship files since deleted
    copy = tmp_path / "source"
    shutil.copytree(root / "src", copy / "src",
                    ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(root / name, copy / name)
    out = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps",
                          "--no-build-isolation", "-q", "-w", str(tmp_path), str(copy)],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    (wheel,) = tmp_path.glob("reliefkit-*.whl")
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
    assert {name for name in names if name.endswith(".glsl")} == shaders
    assert page <= names  # `reliefkit view` needs no Node: the bundle ships
