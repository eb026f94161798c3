"""`export`: a representation as a glTF 2.0 file (.glb or .gltf) that any viewer shows.

The file holds one scene with one node per representation. That node carries reliefkit's
extension ``RELIEFKIT_<kind>`` (declared in ``extensionsUsed`` only, never required:
Babylon, Godot, Unity's glTFast and Blender refuse files with an unknown required
extension) with the representation's arrays and params (`io.gltf.representation`: what
`load` reads back bit for bit) and its draw plans (`export.draw`), and ``extras.reliefkit``
(kind, kind version, params, source hash, the bake's report). Its child node holds the core
glTF a viewer that knows nothing of reliefkit draws: the representation's own
`fallback_mesh` (`io.gltf.mesh` writes it), so the extension's data stays in the scene's
coordinates whatever transform the fallback needs. docs/gltf.md is the specification.
"""

from __future__ import annotations

from pathlib import Path

from .. import __version__
from ..errors import FormatError, UsageError
from ..io import rk
from ..io.gltf.files import gltf_builder, write_gltf
from ..io.gltf.glb import GlbBuilder, write_glb
from ..io.gltf.mesh import add_render_mesh
from ..io.gltf.representation import extension_name, representation_extension
from ..scene.mesh import RenderMesh
from .draw import draw_extension

__all__ = ["export", "export_bytes", "representation_node", "builder_for", "write_document",
           "DEFAULT_FALLBACK_TRIANGLES", "GENERATOR"]

DEFAULT_FALLBACK_TRIANGLES = 20_000
GENERATOR = f"reliefkit {__version__}"


def builder_for(path) -> GlbBuilder:
    """A builder for ``path``: images in the buffer for .glb, files beside a .gltf."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in (".glb", ".gltf"):
        raise UsageError(f"cannot export to {path}: name a .glb or .gltf file")
    return _generated(gltf_builder(path) if suffix == ".gltf" else GlbBuilder())


def _generated(builder: GlbBuilder) -> GlbBuilder:
    builder.document["asset"]["generator"] = GENERATOR
    return builder


def fallback_of(rep, triangles: int) -> RenderMesh:
    """What a viewer without reliefkit's extension shows of ``rep``."""
    if isinstance(rep, RenderMesh):
        return rep
    make = getattr(rep, "fallback_mesh", None)
    if make is None:
        raise UsageError(f"a {type(rep).__name__} has no glTF fallback mesh; export it with "
                         "--no-fallback")
    return make(triangles)


def representation_node(builder: GlbBuilder, rep, *, fallback: bool = True,
                        fallback_triangles: int = DEFAULT_FALLBACK_TRIANGLES,
                        embed_shaders: bool = False, source_hash: str | None = None,
                        name: str | None = None, options: dict | None = None,
                        instrumented: bool = False, cache_key: str | None = None) -> int:
    """Add ``rep``'s node (extension, extras, the fallback as its child) to the builder's
    document; the node's index. ``options``: render options its draw plans are made with;
    ``instrumented``: add the iteration-counting plans (`draw_extension`); ``cache_key``:
    the bake's (`batch.key`), kept in the extras so a batch can tell a stale export."""
    codec, arrays, params = rk.prepare(rep)
    extension = representation_extension(builder, codec, arrays, params)
    extension["draw"] = draw_extension(builder, rep, embed_shaders=embed_shaders,
                                       options=options, instrumented=instrumented)
    ext_name = extension_name(codec.kind)
    report = rep.bake_report() if hasattr(rep, "bake_report") else []
    node = {"name": name or codec.kind, "extensions": {ext_name: extension},
            "extras": {"reliefkit": {"kind": codec.kind, "kindVersion": codec.version,
                                     "params": params, "sourceHash": source_hash,
                                     "report": list(report), "generator": GENERATOR}}}
    if cache_key is not None:  # optional: exports of bakes without one keep their bytes
        node["extras"]["reliefkit"]["cacheKey"] = cache_key
    document = builder.document
    if fallback:
        mesh = fallback_of(rep, fallback_triangles)
        maps = getattr(rep, "fallback_normal_maps", dict)()
        child = add_render_mesh(builder, mesh, name=f"{node['name']} (fallback)",
                                normal_textures=maps)
        document.setdefault("nodes", []).append(child)
        node["children"] = [len(document["nodes"]) - 1]
    document.setdefault("nodes", []).append(node)
    used = document.setdefault("extensionsUsed", [])
    if ext_name not in used:
        used.append(ext_name)
        used.sort()
    return len(document["nodes"]) - 1


def _one_scene(builder: GlbBuilder, roots: list[int]) -> None:
    builder.document["scenes"] = [{"nodes": roots}]
    builder.document["scene"] = 0


def write_document(path, builder: GlbBuilder, roots: list[int]) -> Path:
    """One scene of the ``roots`` nodes, written atomically as .glb or .gltf."""
    _one_scene(builder, roots)
    path = Path(path)
    if path.suffix.lower() == ".gltf":
        return write_gltf(path, builder)
    return write_glb(path, *builder.finish())


def export(rep, path, *, fallback: bool = True,
           fallback_triangles: int = DEFAULT_FALLBACK_TRIANGLES, embed_shaders: bool = False,
           source_hash: str | None = None, cache_key: str | None = None) -> Path:
    """Write ``rep`` as a glTF file (see the module); `reliefkit.load` reads it back.

    Parameters
    ----------
    rep : any representation reliefkit saves (any .rk kind).
    path : ``*.glb`` (one file) or ``*.gltf`` (JSON, ``STEM.bin`` and ``STEM_K.png`` files).
    fallback : write the core glTF mesh viewers show (False: the extension only).
    fallback_triangles : the fallback's triangle budget where its kind has one.
    embed_shaders : add the GLSL ES sources of the draw plans' programs.
    source_hash : SHA-256 of the source file (as in .rk files).
    cache_key : the bake's cache key (as in .rk files), when it has one.
    """
    if type(fallback_triangles) is not int or fallback_triangles < 2:
        raise UsageError(f"fallback_triangles must be an integer >= 2, got {fallback_triangles!r}")
    builder = builder_for(path)
    try:
        root = representation_node(builder, rep, fallback=fallback,
                                   fallback_triangles=fallback_triangles,
                                   embed_shaders=embed_shaders, source_hash=source_hash,
                                   cache_key=cache_key)
    except FormatError as exc:
        raise FormatError(f"cannot export to {path}: {exc}") from None
    return write_document(path, builder, [root])


def export_bytes(rep, *, fallback: bool = True, embed_shaders: bool = False,
                 options: dict | None = None, instrumented: bool = False,
                 source_hash: str | None = None, cache_key: str | None = None) -> bytes:
    """``rep`` as the bytes of a .glb file, made in memory (what `reliefkit view` serves,
    what a batch worker returns), its draw plans made with the render ``options`` it
    declares; ``instrumented`` adds the iteration-counting plans (the page's heat map)."""
    builder = _generated(GlbBuilder())
    _one_scene(builder, [representation_node(builder, rep, fallback=fallback,
                                             embed_shaders=embed_shaders, options=options,
                                             instrumented=instrumented,
                                             source_hash=source_hash,
                                             cache_key=cache_key)])
    return builder.glb()
