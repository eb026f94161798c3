"""The ``draw`` member of reliefkit's glTF extension: a representation's draw plans.

What `render.plan.to_json` makes of the plans a drawable draws with its default options:
``plans``, ``geometries`` and ``textures`` as that JSON, and ``arrays``, each named array as a
typed reference (`io.gltf.arrays`; uint8 textures as PNG images; an encoded texture as its
blocks, with ``mipLevels``: the blocks of the mip levels a GPU gets, each encoded from the
half-size average of the decoded level 0, which no browser could encode), vertex attributes
and indices also as glTF accessors
(``"accessor": i``) so a viewer's loader reads them as it reads any geometry. With shaders
embedded, ``programs`` holds the GLSL ES 3.00 sources that reliefkit's shader loader builds
for every program and define set the plans use (one source of truth with the OpenGL path).
Arrays the plans share with the representation's are stored once (`GlbBuilder` keeps one
bufferView per distinct content).
"""

from __future__ import annotations

import numpy as np

from ..compact.encodings import encoding_of
from ..errors import FormatError
from ..gl.shaders import stage_sources
from ..io.gltf.arrays import array_of, declared, put_array
from ..io.gltf.glb import COMPONENT_TYPES, Glb, GlbBuilder, accessor_array
from ..io.rk import decoded_array, stored_form
from ..render.plan import from_json, to_json
from ..render.registry import make_drawables

__all__ = ["counts_iterations", "draw_extension", "read_plans"]

_ACCESSOR_WIDTHS = (1, 2, 3, 4, 16)


def draw_extension(builder: GlbBuilder, rep, *, embed_shaders: bool = False,
                   options: dict | None = None, instrumented: bool = False) -> dict:
    """The ``draw`` object of ``rep``'s extension (see the module): its plans with its
    render defaults, or with ``options`` (render options it declares: `reliefkit view`).
    ``instrumented`` adds ``instrumented``: the same form for the iteration-counting variant
    (`render(..., count_iterations=True)`), where ``rep``'s drawable counts loop iterations
    (the page's heat map); its arrays equal to the plain plans' are stored once."""
    options = dict(options or {})
    (drawable,) = make_drawables([rep], options)
    out = _plans_object(builder, drawable.plans, embed_shaders)
    if instrumented:
        (counting,) = make_drawables([rep], options, instrument=True)
        if counts_iterations(counting):
            out["instrumented"] = _plans_object(builder, counting.plans, embed_shaders)
    return out


def counts_iterations(drawable) -> bool:
    """Whether ``drawable`` (made with ``instrument=True``) writes loop counts: an extra
    attachment, and a shader with a loop (a mesh's or billboard cloud's counts only
    fragments: ``counts_iterations = False``)."""
    return bool(getattr(drawable, "extra_attachments", 0)) and \
        getattr(drawable, "counts_iterations", True)


def _plans_object(builder: GlbBuilder, plans, embed_shaders: bool) -> dict:
    """``plans`` as `render.plan.to_json`'s document with its arrays as typed references
    (and the programs' GLSL ES sources)."""
    document, arrays = to_json(plans)
    geometry, images = _geometry_arrays(document), _texture_arrays(document)
    refs = {}
    for name, array in arrays.items():
        stored, encoding = stored_form(array)
        ref = put_array(builder, stored, png=name in images and encoding is None)
        if encoding is not None:  # a texture's decoded values: stored as its blocks
            ref["encoding"] = encoding
            chain = encoding_of(array).levels[1:]  # the mip levels a GPU gets, re-encoded
            if chain:
                ref["mipLevels"] = [put_array(builder, level) for level in chain]
        if name in geometry and _accessor_able(array):
            ref["accessor"] = builder.add_array(array)
        refs[name] = ref
    out = {**document, "arrays": refs}
    if embed_shaders:
        out["programs"] = _programs(plans)
    return out


def _geometry_arrays(document: dict) -> set[str]:
    names = set()
    for geometry in document["geometries"].values():
        for attribute in geometry["attributes"].values():
            names.add(attribute["tuple"][0]["array"])
        if isinstance(geometry.get("indices"), dict):
            names.add(geometry["indices"]["array"])
    return names


def _texture_arrays(document: dict) -> set[str]:
    """Texture level 0s: uint8 ones go into PNG images, as the representation's colour does
    (the same pixels, the same image)."""
    return {t["array"]["array"] for t in document["textures"].values()
            if isinstance(t.get("array"), dict)}


def _accessor_able(array: np.ndarray) -> bool:
    return (array.dtype in COMPONENT_TYPES.values() and len(array) > 0
            and (array.ndim == 1 or array.ndim == 2 and array.shape[1] in _ACCESSOR_WIDTHS))


def _programs(plans) -> list[dict]:
    """GLSL ES sources of every (program, defines) the plans draw with, in order met."""
    seen, out = set(), []
    programs = [p.program for p in plans] + [
        q for p in plans if p.multipass is not None for q in p.multipass.programs.values()]
    for program in programs:
        defines = dict(sorted(dict(program.defines).items()))
        key = (program.name, tuple(defines.items()))
        if key in seen:
            continue
        seen.add(key)
        sources = stage_sources(program.name, defines, es=True)
        out.append({"program": program.name, "defines": defines,
                    "vertex": sources.get("vertex_shader"),
                    "fragment": sources.get("fragment_shader")})
    return out


def read_plans(glb: Glb, draw: dict, where: str = "draw") -> list:
    """The draw plans of a ``draw`` object read back from a validated file: arrays from
    their bufferViews and images (accessors cross-checked against them)."""
    if not isinstance(draw, dict) or not isinstance(draw.get("arrays"), dict):
        raise FormatError(f"{where}: no arrays object")
    arrays = {}
    for name, ref in draw["arrays"].items():
        declared(ref, f"{where}: array {name!r}")
        arrays[name] = decoded_array(array_of(glb, ref, f"{where}: array {name!r}"),
                                     ref.get("encoding"))
        if "accessor" in ref:
            index = ref["accessor"]
            if type(index) is not int or not 0 <= index < len(glb.document.get("accessors", [])):
                raise FormatError(f"{where}: array {name!r} names no accessor {index!r}")
            seen = accessor_array(glb, index)
            if not np.array_equal(seen.reshape(arrays[name].shape), arrays[name]):
                raise FormatError(f"{where}: array {name!r} and its accessor differ (forged)")
    try:
        return from_json(draw, arrays)
    except (KeyError, TypeError, ValueError) as exc:
        raise FormatError(f"{where}: the plans do not parse ({exc})") from None
