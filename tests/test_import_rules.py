"""The import rules of docs/architecture.md, checked from the source: the core never imports or
names a technique, techniques never import each other, nothing imports the CLI."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from reliefkit.core.params import options_of
from reliefkit.core.technique import techniques

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "reliefkit"
# the only modules outside techniques/ allowed to name the techniques: the explicit list, the
# composition root that registers it, and the public API, which re-exports their functions
# and classes
ALLOWED = {PACKAGE / "__init__.py", PACKAGE / "builtins.py",
           PACKAGE / "techniques" / "__init__.py"}


def modules():
    return sorted(p for p in PACKAGE.rglob("*.py"))


def module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imported_modules(path: Path) -> set[str]:
    """Absolute names of everything ``path`` imports (relative imports resolved)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = module_name(path).split(".")
    if path.name != "__init__.py":
        package = package[:-1]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            target = ".".join([*base, *(node.module.split(".") if node.module else [])])
            out.add(target)
            out |= {f"{target}.{alias.name}" for alias in node.names}
    return out


def technique_of_path(path: Path) -> str | None:
    rel = path.relative_to(PACKAGE).parts
    return rel[1] if rel[0] == "techniques" and len(rel) > 2 else None


def core_words() -> set[str]:
    """The core's own vocabulary (the fields of a mesh and its materials, the animation
    time): a technique option of the same name (``--texture``) does not make the word the
    technique's."""
    from reliefkit.core.params import ANIMATION_TIME
    from reliefkit.scene.mesh import Material, RenderMesh

    return set(RenderMesh.__annotations__) | set(Material.__annotations__) | {ANIMATION_TIME}


def declared_names():
    """What each technique owns: identifiers (its classes) and strings (kinds, options...),
    less the core's own words."""
    identifiers, strings = set(), set()
    for tech in techniques():
        strings |= {tech.name, *tech.kinds, *(b.name for b in tech.bakers)}
        classes = [*tech.representations, *(d.cls for d in tech.drawables),
                   *(d.options for d in tech.drawables if d.options),
                   *(b.params for b in tech.bakers)]
        identifiers |= {tech.name} | {cls.__name__ for cls in classes}
        identifiers |= {d.factory.__name__ for d in tech.drawables}
        for b in tech.bakers:
            strings |= {opt.name for opt in b.options}
        for d in tech.drawables:
            strings |= {opt.name for opt in d.option_list}
    return identifiers, strings - core_words()


def names_used(path: Path) -> tuple[set[str], set[str]]:
    """Identifiers and string constants of a module, docstrings left out."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                docstrings.add(id(body[0].value))
    idents, strings = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            idents.add(node.id)
        elif isinstance(node, ast.Attribute):
            idents.add(node.attr)
        elif isinstance(node, ast.alias):
            idents.add((node.asname or node.name).split(".")[-1])
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) \
                and id(node) not in docstrings:
            strings.add(node.value)
    return idents, strings


@pytest.mark.parametrize("path", [p for p in modules() if technique_of_path(p) is None
                                  and p not in ALLOWED],
                         ids=lambda p: str(p.relative_to(PACKAGE)))
def test_the_core_never_imports_or_names_a_technique(path):
    imports = imported_modules(path)
    assert not {m for m in imports if m.startswith("reliefkit.techniques")}, \
        f"{path.name} imports a technique"
    identifiers, strings = declared_names()
    idents, consts = names_used(path)
    assert not idents & identifiers, f"names {sorted(idents & identifiers)}"
    assert not consts & strings, f"names {sorted(consts & strings)} in a string"


@pytest.mark.parametrize("path", [p for p in modules() if technique_of_path(p)],
                         ids=lambda p: str(p.relative_to(PACKAGE)))
def test_techniques_never_import_each_other(path):
    mine = technique_of_path(path)
    others = {m for m in imported_modules(path) if m.startswith("reliefkit.techniques.")
              and m.split(".")[2] != mine}
    assert not others, f"{path.name} imports {sorted(others)}"


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_nothing_imports_the_cli(path):
    if path.parent == PACKAGE / "cli":
        return
    assert not {m for m in imported_modules(path) if m == "reliefkit.cli"
                or m.startswith("reliefkit.cli.")}


BATCH = PACKAGE / "batch"
# what the batch package builds on: the layers below it (io, bake, export, render, ...);
# never the CLI, the composition root (it is handed ``setup``) or a technique
BATCH_MAY_NOT = ("reliefkit.cli", "reliefkit.builtins", "reliefkit.techniques")


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_only_the_cli_and_the_root_import_the_batch_package(path):
    if path.parent == BATCH or path.parent == PACKAGE / "cli" or path.name == "builtins.py" \
            and path.parent == PACKAGE:
        return
    assert not {m for m in imported_modules(path) if m == "reliefkit.batch"
                or m.startswith("reliefkit.batch.")}


@pytest.mark.parametrize("path", sorted(BATCH.glob("*.py")), ids=lambda p: p.name)
def test_the_batch_package_imports_only_the_layers_below(path):
    assert not {m for m in imported_modules(path)
                if any(m == n or m.startswith(n + ".") for n in BATCH_MAY_NOT)}


# the draw path's users of GL: the GL layer, the one executor and its multi-pass kinds; and
# outside the draw path the GPU bake passes and the frame-timing harness
GL_USERS = (PACKAGE / "gl", PACKAGE / "render" / "executor.py", PACKAGE / "render" / "multipass",
            PACKAGE / "bake", PACKAGE / "bench" / "timing.py")
# what only the GL layer and the executor may use to make or draw GL objects
GL_MAKERS = ("moderngl", "reliefkit.gl.shaders", "reliefkit.gl.stencil", "reliefkit.gl.timing",
             "reliefkit.render.executor", "reliefkit.render.multipass")


def uses_gl(path: Path) -> set[str]:
    return {m for m in imported_modules(path)
            if any(m == g or m.startswith(g + ".") for g in GL_MAKERS)}


@pytest.mark.parametrize("path", modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_only_the_executor_and_the_gl_layer_touch_gl(path):
    """Drawables describe (draw plans), one executor draws: no technique, and nothing in
    the core outside `GL_USERS` and the code that runs a render, makes GL objects."""
    if any(path == u or u in path.parents for u in GL_USERS):
        return
    allowed = {PACKAGE / "render" / "draw.py": "reliefkit.render.executor",  # runs a render
               PACKAGE / "builtins.py": "reliefkit.gl.shaders",  # the root fills
               # reads the defines a program declares (allowed_defines), makes nothing
               PACKAGE / "render" / "instancing.py": "reliefkit.gl.shaders",
               # builds GLSL ES sources for the glTF extension (stage_sources), makes nothing
               PACKAGE / "export" / "draw.py": "reliefkit.gl.shaders",
               # ... and the viewer page's own two programs
               PACKAGE / "viewer" / "site.py": "reliefkit.gl.shaders"}.get(path)
    used = {m for m in uses_gl(path) if not (allowed and m.startswith(allowed))}
    assert not used, f"{path.name} uses {sorted(used)}"


def test_the_rules_see_violations(tmp_path, monkeypatch):
    """The checker itself: a module that imports and names relief is caught."""
    bad = PACKAGE / "bad_module_for_the_test.py"
    monkeypatch.setattr(Path, "read_text", lambda self, encoding=None: (
        "from .techniques.relief import ReliefTexture\nx = 'relief-cube'\n"))
    assert "reliefkit.techniques.relief" in imported_modules(bad)
    idents, consts = names_used(bad)
    identifiers, strings = declared_names()
    assert "ReliefTexture" in idents & identifiers and "relief-cube" in consts & strings
    monkeypatch.setattr(Path, "read_text", lambda self, encoding=None: (
        "import moderngl\nfrom .gl.shaders import program\n"))
    assert uses_gl(bad) == {"moderngl", "reliefkit.gl.shaders", "reliefkit.gl.shaders.program"}


def test_every_option_class_is_declared_with_param():
    for tech in techniques():
        for b in tech.bakers:
            assert options_of(b.params)
