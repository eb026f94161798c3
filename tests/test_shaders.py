"""Shader loader: includes with #line, define variants, compile errors naming file and line."""

import pytest

from reliefkit.errors import GPUError
from reliefkit.gl import shaders

FILES = {
    "prog.glsl": "//! defines: RED GREEN\n#if defined VERTEX_SHADER\nin vec2 p;\n"
                 "void main() { gl_Position = vec4(p, 0.0, 1.0); }\n#endif\n"
                 "#if defined FRAGMENT_SHADER\n#include \"include/col.glsl\"\nout vec4 c;\n"
                 "void main() { c = col(); }\n#endif\n",
    "include/col.glsl": "vec4 col() {\n#if defined RED\n  return vec4(1, 0, 0, 1);\n#else\n"
                        "  return vec4(0, 1, 0, 1);\n#endif\n}\n",
    "broken.glsl": "#if defined VERTEX_SHADER\nvoid main() { gl_Position = vec4(0.0); }\n#endif\n"
                   "#if defined FRAGMENT_SHADER\n#include \"include/bad.glsl\"\nout vec4 c;\n"
                   "void main() { c = bad(); }\n#endif\n",
    "include/bad.glsl": "vec4 bad() {\n  return undefined_thing;\n}\n",
    "loop.glsl": "#include \"loop.glsl\"\n",
}


@pytest.fixture
def fake_files(monkeypatch):
    def read(name):
        if name not in FILES:
            raise GPUError(f"shader file not found: shaders/{name}")
        return FILES[name]

    monkeypatch.setattr(shaders, "read_shader_file", read)
    monkeypatch.setattr(shaders, "_programs", {})


def test_stage_sources_have_version_stage_defines_and_line(fake_files):
    src = shaders.stage_sources("prog.glsl", {"RED": True})
    assert set(src) == {"vertex_shader", "fragment_shader", "_files"}
    frag = src["fragment_shader"].splitlines()
    assert frag[0] == "#version 330 core"
    assert "#define FRAGMENT_SHADER" in frag and "#define RED" in frag
    assert "#line 100001 1" in frag  # the include is file 1 and starts at its line 1
    assert "#line 8 0" in frag  # back in prog.glsl after the include on line 7
    assert src["_files"] == ["prog.glsl", "include/col.glsl"]


def test_unknown_define_is_an_error(fake_files):
    with pytest.raises(GPUError, match="unknown define.*BLUE.*known: GREEN, RED"):
        shaders.stage_sources("prog.glsl", {"BLUE": True})


def test_include_depth_is_limited(fake_files):
    with pytest.raises(GPUError, match="nested deeper"):
        shaders.stage_sources("loop.glsl")


def test_variants_compile_and_differ(gl, fake_files):
    red = shaders.program(gl, "prog.glsl", {"RED": True})
    green = shaders.program(gl, "prog.glsl", {})
    assert red is not green
    assert shaders.program(gl, "prog.glsl", {"RED": True}) is red  # cached


def test_compile_error_names_the_included_file_and_line(gl, fake_files):
    with pytest.raises(GPUError, match=r"shaders/include/bad\.glsl:2: .*undefined_thing"):
        shaders.program(gl, "broken.glsl")


def test_package_shaders_compile(gl):
    shaders.program(gl, "mesh.glsl", {"HAS_TEXTURE": True})
    shaders.program(gl, "mesh.glsl", {})
