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
when it lies within `depth_images.VISIBLE_TEXELS` of k's first surface; ``visibility=False`` is the
paper's texturing); lit with the blended normal unless ``unlit``.

The drawable is one draw plan (`render.plan`): the six images as texture arrays, and the
object's box (ray casting) or the cube (slices) as geometry. Its view hook sets the box's
camera-relative uniforms and either the proxy's faces to cull or the frame's slice stack
(new vertex and index arrays, nearest slice first); the stencil passes are the executor's
"stencil-count" multi-pass kind, one test per image.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...bake.project import axis_frame
from ...compact.encodings import encoding_of
from ...core.params import param
from ...core.technique import DrawableSpec, ProgramVariant
from ...errors import UsageError
from ...gl.uniforms import box_uniforms
from ...render.instancing import instance_safe, per_object
from ...render.plan import (
    Attribute,
    DrawPlan,
    Geometry,
    MultiPass,
    Program,
    Texture,
    ViewHook,
    ViewUpdate,
)
from ...render.proxy import PROXY_RASTER, Proxy, box_planes, convex_proxy, cull_face
from .depth_images import FACE_INDEX, check_memory, visible_depth
from .representation import DepthObject
from .slices import auto_slice_count, orthogonal_slices, screen_slices, view_direction

PROGRAM = "slicing:depth_object.glsl"
COPY_PROGRAM = "slicing:copy_frame.glsl"
SLICINGS = ("orthogonal", "screen", "raycast")
PASSES = ("single", "stencil")
TEXTURINGS = ("blend3", "nearest")
ALPHA_TESTS = ("point", "slab")
EMPTY_DEPTH = 2.0          # uploaded for texels whose column is empty: no test can pass
FINEST_TEXELS = 0.5        # automatic slices: never closer than half a texel (a slice hit
                           # lies up to one spacing / cos(angle) behind the exact one)
PROGRAMS = tuple(ProgramVariant(PROGRAM, d) for d in (
    {}, {"HULL": True}, {"TEXTURING_NEAREST": True}, {"UNLIT": True}, {"TEST_ONE": True},
    {"COLOR_ONLY": True}, {"SLAB": True}, {"RAYCAST": True}, {"RAYCAST": True, "HULL": True},
    {"RAYCAST": True, "INSTANCED": True},
    {"RAYCAST": True, "HULL": True, "INSTANCED": True, "COUNT_ITERATIONS": True})) + (
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
    return [tuple(float(x) for x in axis_frame(face)[2])
            for face in sorted(FACE_INDEX, key=FACE_INDEX.get)]


def _mat4_list(matrices) -> list[tuple]:
    """A ``mat4 name[n]`` uniform's value: each matrix column-major."""
    return [tuple(float(x) for x in np.asarray(m, np.float64).T.ravel()) for m in matrices]


class DepthObjectDrawable:
    """The six images of one depth object (or hull) as one draw plan, sliced or ray cast
    per camera by its view hook."""

    def __init__(self, rep: DepthObject, options: DepthObjectRenderOptions | None = None,
                 instrument: bool = False):
        self.rep = rep
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
        check_memory(rep.resolution, "render")
        self.plans = [self._plan()]

    def _plan(self) -> DrawPlan:
        rep, opts = self.rep, self.options
        images = rep.images
        cube_to_face = [np.linalg.inv(images.box_to_world[k]) @ images.cube_to_world
                        for k in range(6)]
        uniforms = {"u_res": rep.resolution, "u_face_normal": _face_normals(),
                    "u_max_steps": 3 * rep.resolution + 3,
                    "u_check_visibility": opts.visibility,
                    "u_cube_to_face": _mat4_list(cube_to_face)}
        defines = {"HULL": rep.hull, "TEXTURING_NEAREST": opts.texturing == "nearest",
                   "UNLIT": opts.unlit, "COUNT_ITERATIONS": bool(self.extra_attachments)}
        make = self._ray_cast_plan if opts.slicing == "raycast" else self._slices_plan
        return make(defines, uniforms, name="visual hull" if rep.hull else "depth object",
                    textures=_textures(images))

    def _ray_cast_plan(self, defines: dict, uniforms: dict, **shared) -> DrawPlan:
        """The object's box (its `bounds`), not the whole cube: views hug the bounds with
        their near and far planes, which would clip the cube's corners."""
        rep = self.rep
        lo, hi = rep.bounds
        box = np.diag([*(hi - lo), 1.0])
        box[:3, 3] = lo
        proxy, cube = _box_proxy(box, rep.images.cube_to_world, 0.5 * (lo + hi))
        return DrawPlan(
            program=Program(PROGRAM, defines | {"RAYCAST": True}),
            geometry=_geometry(proxy.positions, cube, proxy.triangles),
            uniforms=uniforms | {"u_visible_depth": visible_depth(rep.resolution)},
            raster=PROXY_RASTER,
            origin=tuple(float(x) for x in proxy.origin),
            per_view=ViewHook(f"{__name__}:ray_cast_view", {
                "cube_to_world": rep.images.cube_to_world, "planes": proxy.planes,
                "texturing": self.options.texturing}), **shared)

    def _slices_plan(self, defines: dict, uniforms: dict, **shared) -> DrawPlan:
        """The cube, which the view hook replaces by each frame's slices; the stencil
        passes are the "stencil-count" kind, one test per tested image."""
        rep, opts = self.rep, self.options
        cube_to_world = rep.images.cube_to_world
        centre = cube_to_world[:3, 3] + 0.5 * rep.images.side
        proxy, cube = _box_proxy(cube_to_world, cube_to_world, centre)
        multipass = None
        if opts.passes == "stencil":
            program = Program(PROGRAM, defines | {"COLOR_ONLY": True})
            multipass = MultiPass("stencil-count", {
                "test": Program(PROGRAM, defines | {"TEST_ONE": True}), "color": program,
                "copy": Program(COPY_PROGRAM)}, {"uniform": "u_face",
                                                 "values": rep.tested_faces})
        else:
            program = Program(PROGRAM, defines | {"SLAB": self.alpha_test == "slab"})
        return DrawPlan(
            program=program,
            geometry=_geometry(proxy.world_positions - centre, cube, proxy.triangles),
            uniforms=uniforms, origin=tuple(float(x) for x in centre), multipass=multipass,
            per_view=ViewHook(f"{__name__}:slices_view", {
                "cube_to_world": cube_to_world, "resolution": rep.resolution,
                "slicing": opts.slicing, "slices": opts.slices, "passes": opts.passes,
                "alpha_test": self.alpha_test, "texturing": opts.texturing}), **shared)

    def finish(self, frame, stats: dict) -> None:
        covered = int(frame.mask.sum())
        frame.stats.update(stats)
        if "fill_pixels" in stats:
            frame.stats["fill_per_covered_pixel"] = (
                stats["fill_pixels"] / covered if covered else 0.0)


def _textures(images) -> dict:
    """The images as texture arrays (layer k = face k): depth (empty texels at
    `EMPTY_DEPTH`), colour (straight alpha, linear) and normals as they are, or as their
    encodings (`reliefkit.compact`) where compressed: the shader filters the colour and
    normals itself, premultiplied and masked by the exact depth (texturing.glsl), so an
    empty texel adds nothing whatever it decodes to."""
    return {"u_depth": Texture(np.where(images.mask, images.depth, np.float32(EMPTY_DEPTH)),
                               "2d_array", filter="nearest", what="depth images"),
            "u_color": Texture(images.color, "2d_array", filter="nearest",
                               what="depth-image colours", encoded=encoding_of(images.color)),
            "u_normals": Texture(images.normal, "2d_array", filter="nearest",
                                 what="depth-image normals",
                                 encoded=encoding_of(images.normal))}


def _box_proxy(box, cube_to_world, near) -> tuple[Proxy, np.ndarray]:
    """A box's proxy (`render.proxy`, solved around ``near``) and its corners' cube
    coordinates."""
    proxy = convex_proxy(box_planes(np.linalg.inv(box)), near=near)
    corners = proxy.world_positions
    return proxy, (np.c_[corners, np.ones(len(corners))] @ np.linalg.inv(cube_to_world).T)[:, :3]


def _vertices(positions, cube) -> dict:
    """The shader's ``in_position`` (float32, relative to the plan's origin) and
    ``in_cube`` (the vertices' cube coordinates)."""
    return {"in_position": np.asarray(positions, np.float32),
            "in_cube": np.asarray(cube, np.float32)}


def _geometry(positions, cube, triangles) -> Geometry:
    return Geometry({name: Attribute(a) for name, a in _vertices(positions, cube).items()},
                    indices=np.asarray(triangles, np.uint32))


def slice_stack(cube_to_world, resolution: int, slicing: str, slices: int | None, camera):
    """The slices of the cube for ``camera`` (slices.py), nearest first: ``slices`` of
    them, or automatically one per pixel of the cube on screen, never closer than
    `FINEST_TEXELS`."""
    side = float(np.linalg.norm(cube_to_world[:3, 0]))
    centre = cube_to_world[:3, 3] + 0.5 * side
    if slicing == "orthogonal":
        thickness = side
    else:
        f = view_direction(camera, centre)
        thickness = side * float(np.abs(f).sum())  # the cube's extent along f
    count = slices or auto_slice_count(thickness, camera, centre,
                                       side / resolution * FINEST_TEXELS)
    make = orthogonal_slices if slicing == "orthogonal" else screen_slices
    return make(cube_to_world, camera, count)


@instance_safe
def ray_cast_view(plan, camera, light, *, cube_to_world, planes, texturing) -> ViewUpdate:
    """View hook of ray casting: the box's uniforms and the proxy's faces to cull."""
    geometry = plan.geometry
    proxy = Proxy(geometry.attributes["in_position"].array, geometry.indices, planes,
                  np.asarray(plan.origin, np.float64))
    return ViewUpdate(uniforms=box_uniforms(camera, cube_to_world),
                      cull=cull_face(proxy, camera),
                      stats={"slicing": "raycast", "slices": 0, "passes": "single",
                             "texturing": texturing})


@per_object("it cuts a new slice stack through the object's own cube for each "
            "camera")
def slices_view(plan, camera, light, *, cube_to_world, resolution, slicing, slices, passes,
                alpha_test, texturing) -> ViewUpdate:
    """View hook of slicing: this frame's slice stack as the vertex and index arrays,
    nearest slice first; for the stencil passes each slice's index range."""
    stack = slice_stack(cube_to_world, resolution, slicing, slices, camera)
    side = float(np.linalg.norm(cube_to_world[:3, 0]))
    slack = stack.spacing / side if alpha_test == "point" else 0.0
    stats = {"slicing": slicing, "slices": stack.slice_count, "passes": passes,
             "texturing": texturing, "alpha_test": alpha_test,
             "slice_polygons": int(np.count_nonzero(np.diff(stack.first_triangle))),
             "fill_pixels": stack.area_pixels(camera)}
    params = {}
    if passes == "stencil":
        sizes = np.diff(stack.first_triangle)[stack.front_to_back]  # triangles, draw order
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        drawn = sizes > 0
        params["ranges"] = 3 * np.stack([starts[drawn], sizes[drawn]], axis=1)
    else:
        stats["draws"] = 1
    return ViewUpdate(
        uniforms=box_uniforms(camera, cube_to_world) | {
            "u_visible_depth": visible_depth(resolution, slack),
            "u_slice_normal": tuple(float(x) for x in stack.plane_normal),
            "u_slice_spacing": stack.spacing or side},
        attributes=_vertices(stack.positions - np.asarray(plan.origin, np.float64),
                             stack.box),
        indices=np.asarray(stack.triangles_in_order(front_to_back=True), np.uint32),
        params=params, stats=stats)


def drawable_spec() -> DrawableSpec:
    return DrawableSpec(DepthObject, DepthObjectDrawable, DepthObjectRenderOptions)


__all__ = ["DepthObjectDrawable", "DepthObjectRenderOptions", "PROGRAMS", "drawable_spec"]
