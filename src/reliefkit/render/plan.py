"""Draw plans: what a drawable draws, as plain data, with no GL in it.

A `DrawPlan` names a program (a namespaced shader and its defines), its geometry (vertex
arrays, an index array, the primitive), its textures (arrays with their format and sampler
state), its uniforms, its raster state and the pass it belongs to. What changes with the view
(the shell's visibility order, slice stacks, the faces of a proxy to cull, box matrices
relative to the camera) comes from a `ViewHook`: a function named by its import path plus
plain data, called per camera, that returns a `ViewUpdate` of new arrays and uniforms, never
GL calls. `render.executor` is the one place that turns plans into GL objects and draws them;
export and the browser viewer read the same plans.

A plan serializes to JSON plus named arrays (`to_json`, `from_json`) without loss: shared
arrays, geometries and textures stay shared, tuples stay tuples.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..compact.encodings import EncodedImage

PRIMITIVES = ("triangles", "points", "lines", "triangle_strip")
#: The passes every executor has; techniques name multi-pass kinds of their own in
#: `DrawPlan.multipass`.
PASSES = ("opaque", "transparent")
CULL = ("none", "back", "front")
BLEND = ("none", "under", "add")
FILTERS = ("linear", "nearest")
WRAPS = ("clamp", "repeat")
TARGETS = ("2d", "3d", "2d_array")


@dataclass(frozen=True)
class Program:
    """A namespaced shader (``"relief:relief.glsl"``) and the defines of its variant."""

    name: str
    defines: Mapping[str, bool | int] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Attribute:
    """One vertex array: (N, k) float32 or int32, per vertex or per instance."""

    array: np.ndarray
    per_instance: bool = False


@dataclass(frozen=True, eq=False)
class Geometry:
    """Vertex arrays by attribute name, an optional uint32 index array, the primitive;
    ``vertices`` counts the vertices of a draw without arrays (a full-screen triangle, 12
    per instanced tetrahedron) and ``instances`` the instances of an instanced draw."""

    attributes: Mapping[str, Attribute] = field(default_factory=dict)
    indices: np.ndarray | None = None
    primitive: str = "triangles"
    vertices: int | None = None
    instances: int | None = None

    def __post_init__(self):
        if self.primitive not in PRIMITIVES:
            raise ValueError(f"primitive {self.primitive!r} is none of {PRIMITIVES}")


@dataclass(frozen=True, eq=False)
class Texture:
    """A texture as an array and its sampler state. ``target`` "2d": (H, W[, C]); "3d" and
    "2d_array": (D, H, W[, C]), indexed [w, v, u] (a 2D array's layers along D); row 0 is
    v = 0. uint8 is normalised (sRGB-decoded with ``srgb``), float32 stays float, uint16 is
    an unsigned integer texture. ``mipmaps``: built from level 0 by the GL; ``levels``:
    given level arrays (level 0 first) instead. ``wrap``: per axis (u, v[, w]).
    ``encoded``: the array block-compressed or quantized (`reliefkit.compact`), uploaded as
    it is where the GL samples its format (with its own mip levels); ``array`` then holds
    its decoded values, the fallback. A program declaring ``vec2 <sampler>_decode`` gets
    the encoding's (scale, bias) from unorm to the array's values, or (1, 0) for the
    array itself."""

    array: np.ndarray
    target: str = "2d"
    srgb: bool = False
    filter: str = "linear"
    mipmaps: bool = False
    levels: tuple[np.ndarray, ...] | None = None
    wrap: tuple[str, ...] = ("clamp", "clamp", "clamp")
    what: str = "texture"
    encoded: EncodedImage | None = None

    def __post_init__(self):
        if self.target not in TARGETS or self.filter not in FILTERS or \
                any(w not in WRAPS for w in self.wrap):
            raise ValueError(f"{self.what}: bad texture state {self.target}, {self.filter}, "
                             f"{self.wrap}")
        if self.encoded is not None and tuple(self.encoded.shape) != self.array.shape:
            raise ValueError(f"{self.what}: its encoding stands for a {self.encoded.shape} "
                             f"array, not {self.array.shape}")


@dataclass(frozen=True)
class Raster:
    """Fixed-function state of a draw. ``blend`` "under" is the transparent pass's front-
    to-back compositing (`gl.targets.use_transparent_blending`), "add" sums sources.
    ``depth_func`` "<=" with ``depth_clamp`` is how proxies are drawn (`render.proxy`)."""

    depth_test: bool = True
    depth_write: bool = True
    depth_func: str = "<"
    depth_clamp: bool = False
    cull: str = "none"
    front_face: str = "ccw"
    blend: str = "none"

    def __post_init__(self):
        if self.cull not in CULL or self.blend not in BLEND or self.depth_func not in ("<", "<="):
            raise ValueError(f"bad raster state {self}")


@dataclass(frozen=True)
class ViewHook:
    """What changes with the view: ``function`` ("package.module:name", inside reliefkit)
    is called as ``function(plan, camera, light, **data)`` and returns a `ViewUpdate`."""

    function: str
    data: Mapping = field(default_factory=dict)

    def __call__(self, plan: DrawPlan, camera, light) -> ViewUpdate:
        return resolve(self.function)(plan, camera, light, **self.data)


@dataclass
class ViewUpdate:
    """A hook's answer for one camera: uniforms to set, vertex arrays (by attribute name) or
    indices to replace, a new vertex/instance count, a new ``count`` of the range drawn (0:
    nothing from this view, a level of detail switched off), the faces to cull, parameters
    of the plan's multi-pass kind (added to ``MultiPass.params``) and statistics for the
    drawable's `finish`. Empty fields leave the plan's own."""

    uniforms: dict = field(default_factory=dict)
    attributes: dict = field(default_factory=dict)
    indices: np.ndarray | None = None
    vertices: int | None = None
    instances: int | None = None
    count: int | None = None
    cull: str | None = None
    params: dict = field(default_factory=dict)
    stats: dict = field(default_factory=dict)


@dataclass(frozen=True)
class MultiPass:
    """A plan drawn by a named multi-pass kind of the executor instead of one draw (the
    shell's half-opacity search, depth peeling, the depth object's stencil counting):
    its extra ``programs`` by role and plain ``params``."""

    kind: str
    programs: Mapping[str, Program] = field(default_factory=dict)
    params: Mapping = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class DrawPlan:
    """One draw of a drawable, as data (see the module docstring).

    ``textures`` map sampler uniform names to textures (the executor picks the units);
    ``uniforms`` hold everything else the plan sets (the executor adds the camera's, the
    light's and ``u_model_offset`` for geometry stored relative to ``origin``); ``first``
    and ``count`` draw a range of the indices (one material of a mesh)."""

    name: str
    program: Program
    geometry: Geometry
    textures: Mapping[str, Texture] = field(default_factory=dict)
    uniforms: Mapping = field(default_factory=dict)
    raster: Raster = Raster()
    render_pass: str = "opaque"
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    first: int = 0
    count: int | None = None
    per_view: ViewHook | None = None
    multipass: MultiPass | None = None

    def __post_init__(self):
        if self.render_pass not in PASSES:
            raise ValueError(f"{self.name}: pass {self.render_pass!r} is none of {PASSES}")

    def with_view(self, camera, light) -> tuple[DrawPlan, dict]:
        """This plan as drawn from ``camera`` (its hook's update applied) and the hook's
        statistics; itself when it has no hook."""
        if self.per_view is None:
            return self, {}
        update = self.per_view(self, camera, light)
        geometry = self.geometry
        if update.attributes or update.indices is not None or update.vertices is not None \
                or update.instances is not None:
            attributes = {name: replace(attr, array=update.attributes.get(name, attr.array))
                          for name, attr in geometry.attributes.items()}
            geometry = replace(
                geometry, attributes=attributes,
                indices=geometry.indices if update.indices is None else update.indices,
                vertices=geometry.vertices if update.vertices is None else update.vertices,
                instances=geometry.instances if update.instances is None
                else update.instances)
        raster = self.raster if update.cull is None else replace(self.raster, cull=update.cull)
        count = self.count if update.count is None else update.count
        multipass = self.multipass if not update.params else replace(
            self.multipass, params={**self.multipass.params, **update.params})
        return replace(self, geometry=geometry, raster=raster, count=count, multipass=multipass,
                       uniforms={**self.uniforms, **update.uniforms}), update.stats


def resolve(path: str) -> Callable:
    """The function named "package.module:name"; only reliefkit's own (a plan read from a
    file names code to run)."""
    module, _, name = path.partition(":")
    if not module.startswith("reliefkit.") or not name:
        raise ValueError(f"view hook {path!r} is not a reliefkit function")
    return getattr(importlib.import_module(module), name)


# -- serialization ------------------------------------------------------------------------


class _Arrays:
    """Arrays by name, one entry per distinct array object (shared arrays stay shared)."""

    def __init__(self):
        self.named: dict[str, np.ndarray] = {}
        self._ids: dict[int, str] = {}
        self.records: dict[int, str] = {}  # id of a shared geometry or texture -> its key

    def put(self, array: np.ndarray) -> str:
        key = self._ids.get(id(array))
        if key is None:
            key = self._ids[id(array)] = f"a{len(self.named)}"
            self.named[key] = array
        return key


def _encode(value, arrays: _Arrays):
    if isinstance(value, np.ndarray):
        return {"array": arrays.put(value)}
    if isinstance(value, bool | int | float | str) or value is None:
        return value
    if isinstance(value, np.generic):
        return {"scalar": value.dtype.str, "value": value.item()}
    if isinstance(value, EncodedImage):
        return {"encoded": {f.name: _encode(getattr(value, f.name), arrays)
                            for f in fields(value)}}
    if isinstance(value, tuple):
        return {"tuple": [_encode(v, arrays) for v in value]}
    if isinstance(value, list):
        return [_encode(v, arrays) for v in value]
    if isinstance(value, Mapping):
        return {"dict": {k: _encode(v, arrays) for k, v in value.items()}}
    raise TypeError(f"a draw plan cannot hold {type(value).__name__}")


def _decode(value, arrays: Mapping[str, np.ndarray]):
    if isinstance(value, list):
        return [_decode(v, arrays) for v in value]
    if not isinstance(value, dict):
        return value
    if "array" in value:
        return arrays[value["array"]]
    if "scalar" in value:
        return np.dtype(value["scalar"]).type(value["value"])
    if "tuple" in value:
        return tuple(_decode(v, arrays) for v in value["tuple"])
    if "encoded" in value:
        return EncodedImage(**{k: _decode(v, arrays) for k, v in value["encoded"].items()})
    return {k: _decode(v, arrays) for k, v in value["dict"].items()}


def _record(obj, arrays: _Arrays, table: dict, kind: str) -> str:
    """Name of the shared object ``obj`` in ``table`` (a geometry or a texture): numbered
    in the order met, so equal plans give equal documents (an export's bytes)."""
    key = arrays.records.get(id(obj))
    if key is None:
        key = arrays.records[id(obj)] = f"{kind}{len(table)}"
        table[key] = {f.name: _encode(getattr(obj, f.name), arrays) for f in fields(obj)
                      if f.name != "attributes"}
        if kind == "g":
            table[key]["attributes"] = {n: _encode((a.array, a.per_instance), arrays)
                                        for n, a in obj.attributes.items()}
    return key


def to_json(plans) -> tuple[dict, dict[str, np.ndarray]]:
    """``plans`` as a JSON-able document and the arrays it names."""
    arrays, geometries, textures = _Arrays(), {}, {}
    out = []
    for plan in plans:
        entry = {f.name: _encode(getattr(plan, f.name), arrays) for f in fields(plan)
                 if f.name not in ("program", "geometry", "textures", "raster", "per_view",
                                   "multipass")}
        entry["program"] = _encode((plan.program.name, dict(plan.program.defines)), arrays)
        entry["geometry"] = _record(plan.geometry, arrays, geometries, "g")
        entry["textures"] = {n: _record(t, arrays, textures, "t")
                             for n, t in plan.textures.items()}
        entry["raster"] = _encode(_fields(plan.raster), arrays)
        entry["per_view"] = None if plan.per_view is None else _encode(
            (plan.per_view.function, dict(plan.per_view.data)), arrays)
        entry["multipass"] = None if plan.multipass is None else _encode((
            plan.multipass.kind,
            {r: (p.name, dict(p.defines)) for r, p in plan.multipass.programs.items()},
            dict(plan.multipass.params)), arrays)
        out.append(entry)
    return {"plans": out, "geometries": geometries, "textures": textures}, arrays.named


def _fields(obj) -> dict:
    return {f.name: getattr(obj, f.name) for f in fields(obj)}


def from_json(doc: dict, arrays: Mapping[str, np.ndarray]) -> list[DrawPlan]:
    """The plans of `to_json`'s document and arrays."""
    geometries, textures = {}, {}
    for key, g in doc["geometries"].items():
        values = {k: _decode(v, arrays) for k, v in g.items() if k != "attributes"}
        attributes = {n: Attribute(*_decode(a, arrays)) for n, a in g["attributes"].items()}
        geometries[key] = Geometry(attributes=attributes, **values)
    for key, t in doc["textures"].items():
        textures[key] = Texture(**{k: _decode(v, arrays) for k, v in t.items()})
    plans = []
    for entry in doc["plans"]:
        values = {k: _decode(v, arrays) for k, v in entry.items()
                  if k not in ("program", "geometry", "textures", "raster", "per_view",
                               "multipass")}
        name, defines = _decode(entry["program"], arrays)
        hook = _decode(entry["per_view"], arrays)
        multi = _decode(entry["multipass"], arrays)
        plans.append(DrawPlan(
            program=Program(name, defines), geometry=geometries[entry["geometry"]],
            textures={n: textures[k] for n, k in entry["textures"].items()},
            raster=Raster(**_decode(entry["raster"], arrays)),
            per_view=None if hook is None else ViewHook(*hook),
            multipass=None if multi is None else MultiPass(
                multi[0], {r: Program(*p) for r, p in multi[1].items()}, multi[2]),
            **values))
    return plans
