"""The one executor: draw plans (`render.plan`) become GL objects once per context and are
drawn per camera.

`Executor.upload(plans)` creates each distinct texture, vertex array and index array once
(shared objects of several plans are shared here too) and compiles their programs;
`Executor.draw(plan, camera, light)` applies the plan's view hook, writes the arrays it
returned into the uploaded buffers, sets the raster state, binds the textures, sets the
uniforms (the camera's, ``u_model_offset``, the light's, the plan's) and draws, or hands
the plan to its multi-pass kind (`MULTIPASS`). `release()` frees everything in reverse
order of creation. Techniques never touch GL: this module and the multi-pass kinds it
lists are the draw path's only users of moderngl (with `reliefkit.gl`'s helpers).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import moderngl
import numpy as np

from ..gl.context import check_gl_error
from ..gl.shaders import program
from ..gl.targets import FRONT_OPACITY_UNIT
from ..gl.textures import (
    _check_2d,
    check_3d_size,
    check_array_size,
    check_encoded_size,
    encoded_supported,
    encoded_texture,
    texture2d,
    texture3d,
    texture_array,
    texture_levels,
)
from ..gl.uniforms import camera_uniforms, model_offset, set_uniforms
from .multipass import (
    depth_peel,
    half_opacity_search,
    opaque_depth,
    shadow_map,
    stencil_count,
)
from .plan import DrawPlan, Geometry, Program, Texture

GL_DEPTH_CLAMP = 0x864F  # moderngl has no flag for it: enabled through enable_direct
_BLEND = {"under": (moderngl.ONE_MINUS_DST_ALPHA, moderngl.ONE),
          "add": (moderngl.ONE, moderngl.ONE)}
_MODES = {"triangles": moderngl.TRIANGLES, "points": moderngl.POINTS,
          "lines": moderngl.LINES, "triangle_strip": moderngl.TRIANGLE_STRIP}
_VERTEX_FORMATS = {np.dtype(np.float32): "f", np.dtype(np.int32): "i"}


@dataclass
class _Buffer:
    buffer: object
    source: np.ndarray  # the array last written (a hook's new array is written once)


@dataclass
class _Uploaded:
    """A geometry's buffers: one per attribute, the index buffer, and its vertex arrays by
    program (one per program that draws it)."""

    attributes: dict[str, _Buffer]
    indices: _Buffer | None
    vaos: dict = field(default_factory=dict)


class Executor:
    """Uploads plans once into ``ctx`` and draws them from any number of cameras."""

    def __init__(self, ctx):
        self.ctx = ctx
        self._made: list = []                   # every GL object, in creation order
        self._textures: dict[int, object] = {}  # id(Texture) -> GL texture
        self._decode: dict[int, tuple] = {}     # id(GL texture) -> its (scale, bias)
        self._geometry: dict[int, _Uploaded] = {}
        self._keep_alive: list = []             # plan objects whose ids key the tables
        self._viewed: dict[int, Geometry] = {}  # id(geometry) -> its latest view's
        self.groups: dict[int, list] = {}        # id(geometry) -> its multi-pass plans
        self.cache: dict = {}                    # a multi-pass kind's per-light products
        self._full_screen: dict = {}             # vertex arrays of `draw_full_screen`
        self.draw_calls = 0                      # of draw_viewed and draw_full_screen

    # -- upload ---------------------------------------------------------------------------
    def upload(self, plans) -> None:
        """Create the GL objects of ``plans`` not uploaded yet, every texture's size checked
        against the GL limits before any is allocated; on failure everything made so far
        stays owned (and is freed by `release`)."""
        for plan in plans:
            for tex in plan.textures.values():
                if id(tex) not in self._textures:
                    _check_size(self.ctx, tex)
        for plan in plans:
            self._keep_alive.append(plan)
            for tex in plan.textures.values():
                self.texture(tex)
            self._vertex_array(self.program(plan.program), plan.geometry)
            if plan.multipass is not None:
                self.groups.setdefault(id(plan.geometry), []).append(plan)
                for role in plan.multipass.programs.values():
                    self._vertex_array(self.program(role), plan.geometry)
        check_gl_error(self.ctx, "uploading draw plans")

    def program(self, prog: Program):
        """The compiled program (cached on the context by `gl.shaders.program`)."""
        return program(self.ctx, prog.name, dict(prog.defines))

    def keep(self, obj):
        """Own a GL object made for a plan (a multi-pass kind's targets): freed by release."""
        self._made.append(obj)
        return obj

    def texture(self, tex: Texture):
        """The GL texture of ``tex``, uploaded on first use."""
        key = id(tex)
        if key not in self._textures:
            self._keep_alive.append(tex)
            gl_tex = self._textures[key] = self.keep(_upload_texture(self.ctx, tex))
            self._decode[id(gl_tex)] = (tex.encoded.scale, tex.encoded.bias) \
                if _as_encoded(self.ctx, tex) else (1.0, 0.0)
        return self._textures[key]

    def _buffers(self, geometry: Geometry) -> _Uploaded:
        key = id(geometry)
        if key not in self._geometry:
            self._keep_alive.append(geometry)
            attributes = {name: _Buffer(self.keep(self.ctx.buffer(_contiguous(a.array))),
                                        a.array)
                          for name, a in geometry.attributes.items()}
            indices = None if geometry.indices is None else _Buffer(
                self.keep(self.ctx.buffer(_contiguous(geometry.indices, np.uint32))),
                geometry.indices)
            self._geometry[key] = _Uploaded(attributes, indices)
        return self._geometry[key]

    def _vertex_array(self, prog, geometry: Geometry):
        uploaded = self._buffers(geometry)
        key = prog.glo
        if key not in uploaded.vaos:
            content = []
            for name, attr in geometry.attributes.items():
                if name not in prog:
                    continue
                comps = attr.array.shape[1] if attr.array.ndim == 2 else 1
                fmt = f"{comps}{_VERTEX_FORMATS[attr.array.dtype]}"
                content.append((uploaded.attributes[name].buffer,
                                fmt + ("/i" if attr.per_instance else ""), name))
            index = uploaded.indices.buffer if uploaded.indices is not None else None
            uploaded.vaos[key] = self.keep(self.ctx.vertex_array(
                prog, content, index, index_element_size=4))
        return uploaded.vaos[key]

    # -- drawing --------------------------------------------------------------------------
    def view(self, plan: DrawPlan, camera, light) -> tuple[DrawPlan, dict]:
        """``plan`` as seen from ``camera`` (`DrawPlan.with_view`), its new arrays written
        into the uploaded buffers; and the hook's statistics. Only the latest view of a
        geometry is kept (its arrays are what the buffers hold): the views of a list of
        cameras are not all held until the scene is released."""
        viewed, stats = plan.with_view(camera, light)
        if viewed is not plan:
            uploaded = self._buffers(plan.geometry)
            for name, attr in viewed.geometry.attributes.items():
                _write(uploaded.attributes[name], attr.array)
            if viewed.geometry.indices is not None:
                _write(uploaded.indices, viewed.geometry.indices, np.uint32)
            if viewed.geometry is not plan.geometry:
                previous = self._viewed.pop(id(plan.geometry), None)
                if previous is not None:
                    del self._geometry[id(previous)]
                self._viewed[id(plan.geometry)] = viewed.geometry
                self._geometry[id(viewed.geometry)] = uploaded
        return viewed, stats

    def uniforms(self, plan: DrawPlan, camera, light) -> dict:
        """Everything a plan's program is given: the camera's uniforms, ``u_model_offset``,
        the light's, the transparent pass's ``u_front_opacity`` and the plan's own."""
        pass_uniforms = {"u_front_opacity": FRONT_OPACITY_UNIT} \
            if plan.render_pass == "transparent" else {}
        return (camera_uniforms(camera) | model_offset(camera, plan.origin)
                | light.uniforms() | pass_uniforms | dict(plan.uniforms))

    def bind_textures(self, prog, textures: dict, first_unit: int = 0) -> dict:
        """Bind ``textures`` (sampler name -> Texture or GL texture) to units from
        ``first_unit`` on, one unit per distinct texture; returns the sampler uniforms and
        each sampler's ``<sampler>_decode`` (`render.plan.Texture`)."""
        units: dict[int, int] = {}
        samplers = {}
        for name, tex in textures.items():
            gl_tex = self.texture(tex) if isinstance(tex, Texture) else tex
            key = id(gl_tex)
            if key not in units:
                units[key] = first_unit + len(units)
                gl_tex.use(units[key])
            samplers[name] = units[key]
            samplers[f"{name}_decode"] = self._decode.get(key, (1.0, 0.0))
        return samplers

    def set_raster(self, raster) -> None:
        """Apply a `Raster`: enabled tests, depth function, clamp, culling, blending, and
        the depth mask of the bound framebuffer."""
        ctx = self.ctx
        ctx.enable_only((moderngl.DEPTH_TEST if raster.depth_test else 0)
                        | (moderngl.CULL_FACE if raster.cull != "none" else 0)
                        | (moderngl.BLEND if raster.blend != "none" else 0))
        ctx.depth_func = raster.depth_func
        (ctx.enable_direct if raster.depth_clamp else ctx.disable_direct)(GL_DEPTH_CLAMP)
        if raster.cull != "none":
            ctx.cull_face = raster.cull
        ctx.front_face = raster.front_face
        if raster.blend != "none":
            ctx.blend_func = _BLEND[raster.blend]
        ctx.fbo.depth_mask = raster.depth_write

    def reset_raster(self) -> None:
        """Back to the state the passes expect between draws (moderngl's depth function,
        no clamp, depth writes as the bound framebuffer had them)."""
        self.ctx.depth_func = "<"
        self.ctx.disable_direct(GL_DEPTH_CLAMP)

    def draw(self, plan: DrawPlan, camera, light, *, extra_uniforms: dict | None = None,
             textures: dict | None = None, program_override: Program | None = None) -> dict:
        """Draw ``plan`` from ``camera``; returns its view hook's statistics. A multi-pass
        plan goes to its kind. ``extra_uniforms``/``textures`` add to the plan's (a shadow
        map); ``program_override`` draws the geometry with another program (a caster)."""
        viewed, stats = self.view(plan, camera, light)
        if viewed.count == 0:  # switched off from this view
            return stats
        if viewed.multipass is not None and program_override is None:
            stats |= MULTIPASS[viewed.multipass.kind](self, viewed, camera, light,
                                                      extra_uniforms or {}, textures or {})
            return stats
        self.draw_viewed(viewed, camera, light, extra_uniforms=extra_uniforms,
                         textures=textures, program_override=program_override)
        return stats

    def draw_viewed(self, viewed: DrawPlan, camera, light, *, extra_uniforms=None,
                    textures=None, program_override: Program | None = None,
                    raster=None) -> None:
        """One draw of a plan already seen from ``camera`` (`view`)."""
        vao = self.bind(viewed, camera, light, extra_uniforms=extra_uniforms,
                        textures=textures, program_override=program_override)
        self.set_raster(raster or viewed.raster)
        try:
            vao.render(_MODES[viewed.geometry.primitive], **_counts(viewed))
            self.draw_calls += 1
        finally:
            self.reset_raster()

    def draw_full_screen(self, prog: Program, textures: dict, raster) -> None:
        """One full-screen triangle (core:include/fullscreen.glsl) drawn with ``prog``: a
        pass of a multi-pass kind that composites ``textures`` into the bound framebuffer."""
        compiled = self.program(prog)
        key = compiled.glo
        if key not in self._full_screen:
            self._full_screen[key] = self.keep(self.ctx.vertex_array(compiled, []))
        set_uniforms(compiled, self.bind_textures(compiled, textures))
        self.set_raster(raster)
        try:
            self._full_screen[key].render(moderngl.TRIANGLES, vertices=3)
            self.draw_calls += 1
        finally:
            self.reset_raster()

    def bind(self, viewed: DrawPlan, camera, light, *, extra_uniforms=None, textures=None,
             program_override: Program | None = None):
        """Bind the textures and set the uniforms of a draw of ``viewed`` (as `draw_viewed`
        does) and return its vertex array: for multi-pass kinds that draw ranges of it
        themselves, under their own raster state."""
        prog = self.program(program_override or viewed.program)
        vao = self._vertex_array(prog, viewed.geometry)
        samplers = self.bind_textures(prog, {**viewed.textures, **(textures or {})})
        set_uniforms(prog, self.uniforms(viewed, camera, light) | (extra_uniforms or {})
                     | samplers)
        return vao

    def release(self) -> None:
        """Free every GL object, newest first."""
        for obj in reversed(self._made):
            obj.release()
        self._made, self._textures, self._geometry, self._keep_alive = [], {}, {}, []
        self._decode = {}
        self._viewed = {}
        self.groups, self.cache, self._full_screen = {}, {}, {}


def _counts(plan: DrawPlan) -> dict:
    geometry = plan.geometry
    if plan.count is not None:
        count = plan.count
    elif geometry.indices is not None:
        count = geometry.indices.size
    elif geometry.vertices is not None:
        count = geometry.vertices
    else:
        count = min((len(a.array) for a in geometry.attributes.values() if not a.per_instance),
                    default=0)
    out = {"vertices": count, "first": plan.first}
    if geometry.instances is not None:
        out["instances"] = geometry.instances
    return out


def _contiguous(array: np.ndarray, dtype=None) -> bytes:
    return np.ascontiguousarray(array, dtype=dtype).tobytes()


def _write(buffer: _Buffer, array: np.ndarray, dtype=None) -> None:
    if array is buffer.source:
        return
    data = _contiguous(array, dtype)
    if len(data) != buffer.buffer.size:
        buffer.buffer.orphan(len(data))
    buffer.buffer.write(data)
    buffer.source = array


def _check_size(ctx, tex: Texture) -> None:
    """Refuse ``tex`` over the GL limits as `reliefkit.gl.textures` would when creating it
    (sRGB texture arrays are decoded to float16 there: two bytes a channel)."""
    if _as_encoded(ctx, tex):
        check_encoded_size(ctx, tex.encoded, tex.target, tex.what)
        return
    array = tex.levels[0] if tex.levels is not None else tex.array
    shape = array.shape
    if tex.target == "2d" and len(shape) >= 2:
        _check_2d(ctx, shape[1], shape[0], tex.what)
    elif tex.target == "3d" and len(shape) >= 3:
        check_3d_size(ctx, shape[2], shape[1], shape[0], tex.what, nbytes=array.nbytes)
    elif tex.target == "2d_array" and len(shape) >= 3:
        itemsize = 2 if tex.srgb else array.itemsize
        check_array_size(ctx, shape[2], shape[1], shape[0], tex.what,
                         nbytes=array.size * itemsize)


def _as_encoded(ctx, tex: Texture) -> bool:
    """Whether ``tex`` is uploaded in its encoded form (else its array, the decoded values)."""
    return tex.encoded is not None and encoded_supported(ctx, tex.encoded, tex.target,
                                                         _encoded_srgb(tex))


def _encoded_srgb(tex: Texture) -> bool:
    """Whether the GL decodes ``tex``'s encoding from sRGB: as it decodes the array (uint8
    sampled sRGB), or, for a float array, as the encoding stored it (linear colour kept
    sRGB-encoded), so both sample the same values."""
    return tex.srgb if tex.encoded.dtype == "uint8" else tex.encoded.srgb


def _upload_texture(ctx, tex: Texture):
    """A GL texture of ``tex`` through `reliefkit.gl.textures` (sizes checked first)."""
    repeat = tex.wrap[0] == "repeat"
    if _as_encoded(ctx, tex):
        gl_tex = encoded_texture(ctx, tex.encoded, target=tex.target, what=tex.what,
                                 filter=tex.filter, srgb=_encoded_srgb(tex), mipmaps=tex.mipmaps,
                                 repeat=repeat)
    elif tex.target == "2d" and tex.levels is not None:
        gl_tex = texture_levels(ctx, list(tex.levels), what=tex.what)
    elif tex.target == "2d":
        gl_tex = texture2d(ctx, tex.array, what=tex.what, filter=tex.filter, srgb=tex.srgb,
                           mipmaps=tex.mipmaps, repeat=repeat)
    elif tex.target == "3d":
        gl_tex = texture3d(ctx, tex.array, what=tex.what, filter=tex.filter, repeat=repeat)
    else:
        gl_tex = texture_array(ctx, tex.array, what=tex.what, srgb=tex.srgb,
                               mipmaps=tex.mipmaps, filter=tex.filter)
    try:
        gl_tex.repeat_x = tex.wrap[0] == "repeat"
        gl_tex.repeat_y = tex.wrap[1] == "repeat"
        if tex.target == "3d":
            gl_tex.repeat_z = tex.wrap[2] == "repeat"
    except BaseException:
        gl_tex.release()
        raise
    return gl_tex


#: Multi-pass kinds: ``kind(executor, viewed_plan, camera, light, extra_uniforms,
#: textures) -> stats``.
MULTIPASS = {"shadow-map": shadow_map.draw_shadow_mapped,
             "opaque-depth": opaque_depth.draw_with_opaque_depth,
             "half-opacity-search": half_opacity_search.draw_half_opacity_search,
             "depth-peel": depth_peel.draw_depth_peeled,
             "stencil-count": stencil_count.draw_stencil_counted}
