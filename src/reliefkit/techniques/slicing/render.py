"""Drawing depth objects and visual hulls (§4-§5): slices through the cube, or ray casting.

Ray casting (``slicing="raycast"``, the default, beyond the paper): the object's box is
drawn and each pixel's ray walks the N^3 voxels; inside a voxel the nearest-texel object is
one box (see reference.py), so the hit is exact, the same as the CPU reference's, and one
pass costs about as much as a hundred slices.

Slicing (`slicing` orthogonal or screen, the paper's): the cube is cut into a stack of slices
(slices.py), nearest first, and every fragment of a slice is kept only where it lies inside
the volume of every tested image. The slab test (the default) walks the pixel's ray through
the voxels over the slab the slice stands for, so slices are exact at any count too; the
paper's point test checks the slice's own point only, and misses what lies between slices.
``passes="single"`` tests all images in one fragment shader; ``"stencil"``
is §4.1's multi-pass algorithm on a stencil buffer: per slice, one pass per image counts in
the stencil where its test passes (only where the count so far is complete), one pass
textures the pixels whose count is complete and marks them done, one pass resets the rest;
the slices go front to back so the first complete slice wins, with no depth test. The paper
draws colour in every counting pass and erases it with the background; writing colour once,
where the count is complete, gives the same picture; the stencil passes test one image at a
time, so they take the point test.

Texturing (§4.2): the three images closest to the view direction, or the single nearest
(``texturing``), restricted to the images that see the point (a point is seen by image k
when it lies within `VISIBLE_TEXELS` of k's first surface; ``visibility=False`` is the
paper's texturing); lit with the blended normal unless ``unlit``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...errors import UsageError
from ...gl.context import check_gl_error
from ...gl.objects import GLObjects
from ...gl.shaders import program
from ...gl.textures import texture_array
from ...gl.uniforms import box_uniforms, camera_uniforms, model_offset, set_uniforms
from .depth_images import FACE_INDEX, check_memory
from .representation import DepthObject
from .slices import auto_slice_count, orthogonal_slices, screen_slices

PROGRAM = "slicing:depth_object.glsl"
COPY_PROGRAM = "slicing:copy_frame.glsl"
SLICINGS = ("orthogonal", "screen", "raycast")
PASSES = ("single", "stencil")
TEXTURINGS = ("blend3", "nearest")
ALPHA_TESTS = ("point", "slab")
EMPTY_DEPTH = 2.0          # uploaded for texels whose column is empty: no test can pass
FINEST_TEXELS = 0.5        # automatic slices: never closer than half a texel (a slice hit
                           # lies up to one spacing / cos(angle) behind the exact one)
VISIBLE_TEXELS = 1.5       # a point this many texels (plus one slice) behind image k's
                           # surface still counts as seen by image k
_DEPTH_UNIT, _COLOR_UNIT, _NORMAL_UNIT = 0, 1, 2
PROGRAMS = tuple(ProgramVariant(PROGRAM, d) for d in (
    {}, {"HULL": True}, {"TEXTURING_NEAREST": True}, {"UNLIT": True}, {"TEST_ONE": True},
    {"COLOR_ONLY": True}, {"SLAB": True}, {"RAYCAST": True}, {"RAYCAST": True, "HULL": True})) + (
    ProgramVariant(COPY_PROGRAM, {}),)


@dataclass(frozen=True)
class DepthObjectRenderOptions:
    """The render options of depth objects and visual hulls."""

    slicing: str = param("raycast", "no slices: each pixel's ray cast through the images "
                         "(exact); or the paper's slices along the cube axis most "
                         "perpendicular to the view (§3.2), or parallel to the screen cut "
                         "exactly to the cube (§3.3)", choices=SLICINGS)
    slices: int | None = param(None, "number of slices (none: one per pixel of the cube on "
                               "screen, never closer than half a texel)", kind="int", lo=1,
                               hi=16384)
    passes: str = param("single", "test all images in one pass, or count them in the "
                        "stencil buffer one pass per image (§4.1)", choices=PASSES)
    texturing: str = param("blend3", "view-dependent texturing from the three images "
                           "closest to the view, or from the nearest one (§4.2)",
                           choices=TEXTURINGS)
    alpha_test: str | None = param(None, "slices: test the whole slab of the ray the slice "
                                   "stands for (exact at any slice count), or the slice's "
                                   "own point (the paper's alpha test); none: slab, point for "
                                   "the stencil passes", kind="str", choices=ALPHA_TESTS)
    visibility: bool = param(True, "texture each point only from the images that see it "
                             "(off: the paper's texturing, which also paints hidden parts "
                             "with whatever an image saw in front of them)")
    unlit: bool = param(False, "the images' colours without lighting")


def _face_normals() -> list[tuple]:
    """Outward world normal of each face, in face order."""
    from ...bake.project import axis_frame

    return [tuple(float(x) for x in axis_frame(face)[2])
            for face in sorted(FACE_INDEX, key=FACE_INDEX.get)]


def _mat4_array(prog, name: str, matrices) -> None:
    """Write a uniform ``mat4 name[n]`` (column-major), cut to what the compiler kept."""
    if name not in prog:
        return
    length = prog[name].array_length
    data = np.stack([np.asarray(m, np.float64).T for m in matrices[:length]])
    prog[name].write(data.astype(np.float32).tobytes())


class DepthObjectDrawable(GLObjects):
    """The six images of one depth object (or hull) on the GPU, sliced or ray cast per frame."""

    def __init__(self, ctx, rep: DepthObject, options: DepthObjectRenderOptions | None = None,
                 instrument: bool = False):
        self.ctx, self.rep = ctx, rep
        self.options = opts = options or DepthObjectRenderOptions()
        if opts.slicing == "raycast" and opts.passes == "stencil":
            raise UsageError("--passes stencil counts image tests per slice; ray casting "
                             "has no slices (use --slicing orthogonal or screen)")
        self.alpha_test = opts.alpha_test or ("point" if opts.passes == "stencil" else "slab")
        if self.alpha_test == "slab" and opts.passes == "stencil":
            raise UsageError("--alpha-test slab tests all images together; the stencil "
                             "passes test one image at a time (use --alpha-test point)")
        if opts.slicing == "raycast":
            given = [flag for flag, value in (("--slices", opts.slices),
                                              ("--alpha-test", opts.alpha_test)) if value]
            if given:
                raise UsageError(f"{' and '.join(given)} set the slices of --slicing "
                                 "orthogonal or screen; ray casting (the default) has none")
        self.extra_attachments = 1 if instrument and opts.slicing == "raycast" else 0
        self.instrument = instrument
        images = rep.images
        self.centre = images.cube_to_world[:3, 3] + 0.5 * images.side
        self.cube_to_face = [np.linalg.inv(images.box_to_world[k]) @ images.cube_to_world
                             for k in range(6)]
        self.stats: dict = {}
        check_memory(rep.resolution, "render")
        self._upload_owned(self._upload)

    def _upload(self) -> None:
        ctx, images, opts = self.ctx, self.rep.images, self.options
        # One host copy per upload at most, each freed before the next (`RENDER_TEXEL_BYTES`).
        self.depth_tex = self.keep(texture_array(
            ctx, np.where(images.mask, images.depth, np.float32(EMPTY_DEPTH)),
            what="depth images", filter="nearest"))
        premultiplied = images.color.astype(np.float32)
        premultiplied[..., :3] *= premultiplied[..., 3:]
        self.color_tex = self.keep(texture_array(ctx, premultiplied,
                                                 what="depth-image colours"))
        del premultiplied
        self.normal_tex = self.keep(texture_array(ctx, images.normal.astype(np.float32,
                                                                            copy=False),
                                                  what="depth-image normals"))
        common = {"HULL": self.rep.hull, "TEXTURING_NEAREST": opts.texturing == "nearest",
                  "UNLIT": opts.unlit, "COUNT_ITERATIONS": bool(self.extra_attachments)}
        self.vbo = self.ibo = None
        self.vaos: dict = {}
        if opts.slicing == "raycast":
            self.programs = {"main": program(ctx, PROGRAM, common | {"RAYCAST": True})}
            self._cube_proxy()
        elif opts.passes == "stencil":
            self.programs = {"test": program(ctx, PROGRAM, common | {"TEST_ONE": True}),
                             "color": program(ctx, PROGRAM, common | {"COLOR_ONLY": True})}
            self.copy_program = program(ctx, COPY_PROGRAM)
            self.copy_vao = self.keep(ctx.vertex_array(self.copy_program, []))
        else:
            self.programs = {"main": program(ctx, PROGRAM, common | {
                "SLAB": self.alpha_test == "slab"})}
        check_gl_error(ctx, "uploading a depth object")

    def _cube_proxy(self) -> None:
        """The object's box (its `bounds`, inside the cube), not the whole cube: views hug
        the bounds with their near and far planes, which would clip the cube's corners."""
        from ...render.proxy import box_planes, convex_proxy

        cube = self.rep.images.cube_to_world
        lo, hi = self.rep.bounds
        box = np.diag([*(hi - lo), 1.0])
        box[:3, 3] = lo
        self.proxy = convex_proxy(box_planes(np.linalg.inv(box)), near=0.5 * (lo + hi))
        corners = self.proxy.world_positions
        cube_coords = (np.c_[corners, np.ones(len(corners))] @ np.linalg.inv(cube).T)[:, :3]
        self._geometry(self.proxy.positions, cube_coords, self.proxy.triangles, self.proxy.origin)

    def _geometry(self, positions, cube_coords, triangles, origin) -> None:
        """(Re)upload the vertex and index buffers; positions float32 relative to origin."""
        for vao in self.vaos.values():
            vao.release()
        for buf in (self.vbo, self.ibo):
            if buf is not None:
                buf.release()
        self.vaos = {}
        self.vbo = self.ibo = None
        data = np.concatenate([np.asarray(positions, np.float32),
                               np.asarray(cube_coords, np.float32)], axis=1)
        self.vbo = self.ctx.buffer(data.astype(np.float32).tobytes())
        self.ibo = self.ctx.buffer(np.asarray(triangles, np.uint32).tobytes())
        self.geometry_origin = np.asarray(origin, np.float64)
        for name, prog in self.programs.items():
            self.vaos[name] = self.ctx.vertex_array(
                prog, [(self.vbo, "3f 3f", "in_position", "in_cube")], self.ibo,
                index_element_size=4)

    def release(self) -> None:
        for vao in getattr(self, "vaos", {}).values():
            vao.release()
        self.vaos = {}
        for name in ("vbo", "ibo"):
            buf = getattr(self, name, None)
            if buf is not None:
                buf.release()
            setattr(self, name, None)
        super().release()

    # -- per frame ------------------------------------------------------------------------
    def slice_stack(self, camera):
        """The slices of this frame (slices.py), nearest first."""
        images, opts = self.rep.images, self.options
        cube = images.cube_to_world
        if opts.slicing == "orthogonal":
            thickness = images.side
        else:
            from .slices import view_direction

            f = view_direction(camera, self.centre)
            thickness = images.side * float(np.abs(f).sum())  # the cube's extent along f
        count = opts.slices or auto_slice_count(thickness, camera, self.centre,
                                                images.texel * FINEST_TEXELS)
        make = orthogonal_slices if opts.slicing == "orthogonal" else screen_slices
        return make(cube, camera, count)

    def _uniforms(self, camera, light) -> dict:
        return (camera_uniforms(camera) | box_uniforms(camera, self.rep.images.cube_to_world)
                | light.uniforms() | {
                    "u_res": self.rep.resolution, "u_face_normal": _face_normals(),
                    "u_depth": _DEPTH_UNIT, "u_color": _COLOR_UNIT, "u_normals": _NORMAL_UNIT,
                    "u_max_steps": 3 * self.rep.resolution + 3,
                    "u_check_visibility": self.options.visibility})

    def _bind(self, camera, light, extra: dict | None = None) -> None:
        self.depth_tex.use(_DEPTH_UNIT)
        self.color_tex.use(_COLOR_UNIT)
        self.normal_tex.use(_NORMAL_UNIT)
        values = self._uniforms(camera, light) | model_offset(camera, self.geometry_origin) | \
            (extra or {})
        for prog in self.programs.values():
            set_uniforms(prog, values)
            _mat4_array(prog, "u_cube_to_face", self.cube_to_face)

    def draw(self, camera, light) -> None:
        import moderngl

        opts = self.options
        if opts.slicing == "raycast":
            from ...render.proxy import cull_face, proxy_raster_state

            self._bind(camera, light, {"u_visible_depth": self._visible_depth(None)})
            with proxy_raster_state(self.ctx):
                self.ctx.cull_face = cull_face(self.proxy, camera)
                self.vaos["main"].render()
            self.stats = {"slicing": "raycast", "slices": 0, "passes": "single",
                          "texturing": opts.texturing}
            return
        stack = self.slice_stack(camera)
        relative = stack.positions - self.centre
        ordered = stack.triangles_in_order(front_to_back=True)
        self._geometry(relative, stack.box, ordered, self.centre)
        self._bind(camera, light, {"u_visible_depth": self._visible_depth(stack),
                                   "u_slice_normal": tuple(float(x) for x in stack.plane_normal),
                                   "u_slice_spacing": stack.spacing or self.rep.images.side})
        if opts.passes == "stencil":
            draws = self._draw_stencil(camera, stack)
        else:
            self.vaos["main"].render(moderngl.TRIANGLES)
            draws = 1
        self.stats = {"slicing": opts.slicing, "slices": stack.slice_count,
                      "passes": opts.passes, "texturing": opts.texturing, "draws": draws,
                      "alpha_test": self.alpha_test,
                      "slice_polygons": int(np.count_nonzero(np.diff(stack.first_triangle))),
                      "fill_pixels": stack.area_pixels(camera)}

    def _visible_depth(self, stack) -> float:
        """How far behind image k's surface a drawn point may be and still count as seen by
        it (cube-side units): `VISIBLE_TEXELS`, plus a slice spacing for the point test,
        whose points lie up to that far inside the surface."""
        slack = stack.spacing / self.rep.images.side if stack is not None and \
            self.alpha_test == "point" else 0.0
        return VISIBLE_TEXELS / self.rep.resolution + slack

    def _draw_stencil(self, camera, stack) -> int:
        """§4.1's algorithm into a stencil target, then copied into the frame's target."""
        import moderngl

        from ...gl import stencil as st
        from ...gl.targets import FRAME_ATTACHMENTS

        ctx = self.ctx
        frame_fbo = ctx.fbo
        faces = self.rep.tested_faces
        complete = len(faces)
        target = st.StencilTarget(ctx, camera.size, FRAME_ATTACHMENTS)
        draws = 0
        try:
            target.use()
            target.clear()
            ctx.disable(moderngl.DEPTH_TEST)
            first = np.concatenate([[0], np.cumsum(np.diff(stack.first_triangle)[
                stack.front_to_back])])
            test, color = self.vaos["test"], self.vaos["color"]
            for k in range(stack.slice_count):
                start, stop = int(first[k]), int(first[k + 1])
                if stop == start:
                    continue
                span = {"vertices": 3 * (stop - start), "first": 3 * start}
                for i, face in enumerate(faces):
                    target.stencil(st.EQUAL, i, st.INCR, color=False)
                    self.programs["test"]["u_face"].value = face
                    test.render(moderngl.TRIANGLES, **span)
                target.stencil(st.EQUAL, complete, st.INCR, color=True)
                color.render(moderngl.TRIANGLES, **span)
                target.stencil(st.GREATER, complete, st.ZERO, color=False)
                color.render(moderngl.TRIANGLES, **span)
                draws += complete + 2
            target.end()
            frame_fbo.use()
            ctx.enable(moderngl.DEPTH_TEST)
            for unit, tex in enumerate(target.textures):
                tex.use(_NORMAL_UNIT + 1 + unit)
            set_uniforms(self.copy_program, camera_uniforms(camera) | {
                "u_src_color": _NORMAL_UNIT + 1, "u_src_position": _NORMAL_UNIT + 2,
                "u_src_normal": _NORMAL_UNIT + 3})
            self.copy_vao.render(moderngl.TRIANGLES, vertices=3)
            check_gl_error(ctx, "drawing a depth object with stencil passes")
        finally:
            target.end()
            frame_fbo.use()
            ctx.enable(moderngl.DEPTH_TEST)
            target.release()
            frame_fbo.use()
        return draws

    def finish(self, frame) -> None:
        covered = int(frame.mask.sum())
        frame.stats.update(self.stats)
        if "fill_pixels" in self.stats:
            frame.stats["fill_per_covered_pixel"] = (
                self.stats["fill_pixels"] / covered if covered else 0.0)


def drawable_spec() -> DrawableSpec:
    return DrawableSpec(DepthObject, DepthObjectDrawable, DepthObjectRenderOptions)


__all__ = ["DepthObjectDrawable", "DepthObjectRenderOptions", "PROGRAMS", "drawable_spec"]
