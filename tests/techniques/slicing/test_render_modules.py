"""The slicing technique describes its draws as plans; the executor draws them."""

from __future__ import annotations

import pytest
from test_import_rules import PACKAGE, imported_modules

FORBIDDEN = ("moderngl", "reliefkit.gl.shaders", "reliefkit.gl.textures",
             "reliefkit.gl.objects", "reliefkit.gl.stencil", "reliefkit.gl.context",
             "reliefkit.gl.uniforms.set_uniforms",
             "reliefkit.gl.targets.use_transparent_blending")


@pytest.mark.parametrize("module", ["render.py", "displacement_render.py"])
def test_render_modules_create_no_gl_objects(module):
    imports = imported_modules(PACKAGE / "techniques" / "slicing" / module)
    assert not {name for name in imports if name.startswith(FORBIDDEN)}
