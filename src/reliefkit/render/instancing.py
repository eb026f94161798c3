"""Instanced drawing: one object's draw plans at N placements, one draw call per plan.

A placement is a similarity of the world: a uniform scale and a rotation about +y (yaw,
radians, from +z towards +x as `Camera.orbit`'s azimuth) about the world origin, then a
translation; a forest is one tree's plans with a placement per tree. `instanced(plans,
placements)` gives each plan two per-instance attributes (`shaders/include/instancing.glsl`
reads them under ``INSTANCED``): ``in_instance``, the translation from the plan's own origin
to the instance's and the scale, and ``in_instance_yaw``, the rotation's cosine and sine.
The vertex stage places each vertex; ray-casting kinds take the pixel's ray into the
object as it is, through flat varyings, and bring the hit and its normal back out.

Only what is the same for every instance can be drawn so. A plan is refused
(`NotInstanceable`, one line: why) when its program has no ``INSTANCED`` variant, when it is
transparent (its instances would need sorting against each other), multi-pass, instanced
already, or has a view hook that works per object (a visibility sort, slice stacks, a level
of detail chosen by distance). A hook whose answer is the same for every instance (box
matrices relative to the camera) declares it with `instance_safe`; the faces it would cull
are left to the GPU's back-face culling, which the plan's raster state already asks for.
Any other hook declares with `per_object` the reason a user reads when it is refused.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import UsageError
from ..gl.shaders import allowed_defines
from .plan import Attribute, DrawPlan, ViewHook, ViewUpdate, resolve

DEFINE = "INSTANCED"
#: Refused above this: 24 bytes per instance and geometry, allocated before anything is drawn.
MAX_INSTANCES = 1 << 22
_SAFE = "instance_safe"
_PER_OBJECT = "per_object_reason"


class NotInstanceable(UsageError):
    """A plan that one instanced draw cannot draw (the message says why)."""


def instance_safe(hook):
    """Mark a view hook as the same for every instance of an instanced plan (`instanced`
    keeps it, its face culling left to the GPU's back-face culling)."""
    setattr(hook, _SAFE, True)
    return hook


def per_object(reason: str):
    """Mark a view hook as working per object, with ``reason`` (what it does for each
    camera, in a user's words) for the message that refuses to draw it instanced."""
    def mark(hook):
        setattr(hook, _PER_OBJECT, reason)
        return hook

    return mark


def placements(translations, scales=1.0, yaws=0.0) -> np.ndarray:
    """(N, 5) float64 placements [x, y, z, scale, yaw] from N translations and a scale and
    a yaw (radians) each or for all; checked as `instanced` does."""
    t = np.asarray(translations, np.float64)
    if t.ndim != 2 or t.shape[1] != 3:
        raise UsageError(f"instance translations must be (N, 3), got shape {t.shape}")
    n = len(t)
    out = np.column_stack([t, np.broadcast_to(np.asarray(scales, np.float64), (n,)),
                           np.broadcast_to(np.asarray(yaws, np.float64), (n,))])
    return checked(out)


def checked(placements) -> np.ndarray:
    """``placements`` as (N, 5) float64, or a one-line `UsageError`: 1 <= N <=
    `MAX_INSTANCES`, every value finite, every scale positive."""
    p = np.asarray(placements, np.float64)
    if p.ndim != 2 or p.shape[1] != 5:
        raise UsageError(f"placements must be (N, 5) [x, y, z, scale, yaw], got shape {p.shape}")
    if not 1 <= len(p) <= MAX_INSTANCES:
        raise UsageError(f"{len(p)} instances: draw 1 to {MAX_INSTANCES} at once")
    if not np.isfinite(p).all() or not (p[:, 3] > 0).all():
        raise UsageError("placements must be finite with positive scales")
    return p


def instance_attributes(placements: np.ndarray, origin) -> dict[str, np.ndarray]:
    """``in_instance`` (translation from ``origin`` to each instance's image of it, scale)
    and ``in_instance_yaw`` (cos, sin), float32, for geometry stored relative to ``origin``:
    an instance maps a world point p to t + s R p, so a vertex o + v goes to
    o + (t + s R o - o) + s R v, the translation computed here in float64."""
    o = np.asarray(origin, np.float64)
    t, s, yaw = placements[:, :3], placements[:, 3], placements[:, 4]
    c, sn = np.cos(yaw), np.sin(yaw)
    rotated = np.column_stack([c * o[0] + sn * o[2], np.full_like(c, o[1]),
                               -sn * o[0] + c * o[2]])
    offset = t + s[:, None] * rotated - o
    return {"in_instance": np.column_stack([offset, s]).astype(np.float32),
            "in_instance_yaw": np.column_stack([c, sn]).astype(np.float32)}


def instanced(plans, placements) -> list[DrawPlan]:
    """``plans`` drawn at every one of ``placements`` ((N, 5): x, y, z, scale, yaw), one
    draw call each; `NotInstanceable` names the first plan that cannot be."""
    p = checked(placements)
    geometries: dict = {}  # (id(geometry), origin) -> its instanced copy: shared stays shared
    out = []
    for plan in plans:
        refuse_unless_instanceable(plan)
        key = (id(plan.geometry), plan.origin)
        if key not in geometries:
            extra = {name: Attribute(a, per_instance=True)
                     for name, a in instance_attributes(p, plan.origin).items()}
            geometries[key] = replace(plan.geometry, attributes={**plan.geometry.attributes,
                                                                 **extra}, instances=len(p))
        hook = None if plan.per_view is None else ViewHook(
            f"{__name__}:instanced_view",
            {"hook": plan.per_view.function, "data": dict(plan.per_view.data)})
        out.append(replace(plan, geometry=geometries[key], per_view=hook,
                           program=replace(plan.program, defines={**plan.program.defines,
                                                                  DEFINE: True})))
    return out


def refuse_unless_instanceable(plan: DrawPlan) -> None:
    """`NotInstanceable` with the reason ``plan`` cannot be drawn by `instanced`."""
    def refuse(why: str):
        raise NotInstanceable(f"{plan.name} cannot be drawn instanced: {why}")

    if plan.render_pass != "opaque":
        refuse("it is transparent, and one draw of many instances cannot sort them front to "
               "back")
    if plan.multipass is not None:
        refuse(f"its multi-pass kind {plan.multipass.kind!r} draws each object by itself")
    if plan.geometry.instances is not None:
        refuse("its geometry is instanced already (one instance per primitive)")
    hook = None if plan.per_view is None else resolve(plan.per_view.function)
    if hook is not None and not getattr(hook, _SAFE, False):
        reason = getattr(hook, _PER_OBJECT, None)
        refuse("its view hook works per object" + (f" ({reason})" if reason else ""))
    if DEFINE not in allowed_defines(plan.program.name):
        refuse(f"its program {plan.program.name} has no {DEFINE} variant")


def instanced_view(plan: DrawPlan, camera, light, *, hook: str, data: dict) -> ViewUpdate:
    """An `instance_safe` hook's update for every instance: its faces to cull left to the
    plan's own back-face culling (they are the object's, not each instance's)."""
    update = resolve(hook)(plan, camera, light, **data)
    update.cull = None
    return update


class InstancedDrawable:
    """A drawable (`render.registry.make_drawables`) drawn at every placement: its plans
    `instanced`, its ``finish`` kept (the Frame's AOVs are the instances'), and
    ``instances`` in the Frame's stats."""

    def __init__(self, drawable, placements):
        self.drawable = drawable
        placements = checked(placements)
        self.plans = instanced(drawable.plans, placements)
        self.instances = len(placements)
        self.extra_attachments = getattr(drawable, "extra_attachments", 0)

    def finish(self, frame, stats: dict) -> None:
        finish = getattr(self.drawable, "finish", None)
        if finish is not None:
            finish(frame, stats)
        frame.stats["instances"] = frame.stats.get("instances", 0) + self.instances
