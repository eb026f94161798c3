"""The vehicle asset: a delivery van with its detail on the vertical sides."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..mesh import RenderMesh
from .colors import rgb
from .geometry import MeshBuilder, box, box_between, chamfered_prism, lathe, normalize, slab

_PAINTS = ((196, 38, 36), (32, 92, 170), (236, 236, 228), (240, 180, 30), (44, 130, 84))


class _VanShape(NamedTuple):
    """Main dimensions of the van (x: length, y: height, z: width; the ground is y = 0)."""

    half_length: float
    half_width: float
    floor: float  # bottom of the body
    belt: float  # top of the lower body, bottom of the cabin
    roof: float
    wheel_radius: float

    def windshield_x(self, y):
        """Return x on the windshield's outer plane at height `y` (it leans back from the nose)."""
        bottom, top = self.half_length - 0.16, self.half_length - 0.5
        return bottom + (top - bottom) * (np.asarray(y) - self.belt) / (self.roof - self.belt)


def _van_body(builder: MeshBuilder, s: _VanShape, paint: np.ndarray) -> None:
    """Lower body (with a sloped nose) and cabin (with a raked windshield), both chamfered."""
    hl, hw = s.half_length, s.half_width
    lower = [(-hl, s.floor), (hl, s.floor), (hl, s.belt - 0.07), (hl - 0.14, s.belt), (-hl, s.belt)]
    cabin = [
        (-hl, s.belt - 0.02),
        (s.windshield_x(s.belt - 0.02), s.belt - 0.02),
        (s.windshield_x(s.roof), s.roof),
        (-hl, s.roof),
    ]
    builder.add("body", chamfered_prism(lower, (-hw, hw), 0.04), paint)
    builder.add("cabin", chamfered_prism(cabin, (-hw, hw), 0.05), paint)


def _van_wheels(builder: MeshBuilder, s: _VanShape) -> None:
    """Four wheels: rounded tyres with silver rims, five spokes and a hub, set in the sides."""
    r = s.wheel_radius
    tyre = [(r - 0.03, 0.0), (r, 0.025), (r, 0.135), (r - 0.03, 0.16)]
    rim = [(0.62 * r, 0.15), (0.62 * r, 0.168), (0.5 * r, 0.175)]
    hub = [(0.2 * r, 0.17), (0.2 * r, 0.19)]
    for x in (-0.62 * s.half_length, 0.64 * s.half_length):
        for side in (-1.0, 1.0):
            axis = np.array([0.0, 0.0, side])
            base = np.array([x, r, side * (s.half_width - 0.12)])
            builder.add("tyre", lathe(base, axis, tyre, 28), rgb(34, 34, 36))
            builder.add("rim", lathe(base, axis, rim, 28), rgb(188, 190, 196))
            builder.add("hub", lathe(base, axis, hub, 12), rgb(90, 92, 98))
            for k in range(5):
                a = 2.0 * np.pi * k / 5 + 0.3
                spoke_axes = np.column_stack(
                    [[np.cos(a), np.sin(a), 0.0], [-np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]]
                )
                center = base + [0.35 * r * np.cos(a), 0.35 * r * np.sin(a), side * 0.177]
                builder.add(
                    "spoke", box(center, (0.17 * r, 0.035, 0.006), spoke_axes), rgb(150, 152, 160)
                )


def _van_side(builder: MeshBuilder, s: _VanShape, side: float, paint: np.ndarray) -> None:
    """Windows, door seams, handles, a rubbing strip, a marker light and a mirror on one side."""
    hl, hw = s.half_length, s.half_width
    glass, dark = rgb(30, 40, 52), rgb(24, 24, 26)

    def panel(polygon, proud: float, inset: float = 0.01):
        z = (side * (hw - inset), side * (hw + proud))
        return slab(np.asarray(polygon, dtype=np.float64), z)

    lo, hi = s.belt + 0.08, s.roof - 0.08
    front = [(0.2, lo), (s.windshield_x(lo) - 0.07, lo), (s.windshield_x(hi) - 0.07, hi), (0.2, hi)]
    builder.add("window", panel(front, 0.006), glass)
    for x0, x1 in ((-0.42, 0.12), (-0.9, -0.5)):
        builder.add("window", panel([(x0, lo), (x1, lo), (x1, hi), (x0, hi)], 0.006), glass)
    for x in (0.16, -0.46):  # door seams, floor to roof
        builder.add(
            "seam",
            panel(
                [
                    (x - 0.006, s.floor + 0.04),
                    (x + 0.006, s.floor + 0.04),
                    (x + 0.006, s.roof - 0.04),
                    (x - 0.006, s.roof - 0.04),
                ],
                0.003,
            ),
            dark,
        )
    for x in (0.26, 0.06):  # handles
        builder.add(
            "handle",
            box_between(
                (x - 0.04, s.belt - 0.06, side * (hw - 0.01)),
                (x + 0.04, s.belt - 0.035, side * (hw + 0.022)),
            ),
            dark,
        )
    strip_y = s.floor + 0.12
    builder.add(
        "strip",
        box_between(
            (-0.36 * hl / 0.62, strip_y, side * (hw - 0.01)),
            (0.36, strip_y + 0.05, side * (hw + 0.012)),
        ),
        rgb(60, 60, 64),
    )
    builder.add(
        "marker",
        box_between(
            (0.86 * hl, strip_y, side * (hw - 0.01)),
            (0.93 * hl, strip_y + 0.04, side * (hw + 0.008)),
        ),
        rgb(255, 150, 20),
    )
    mirror_x, mirror_y = s.windshield_x(s.belt + 0.06) - 0.03, s.belt + 0.12
    builder.add(
        "mirror", box((mirror_x, mirror_y - 0.04, side * (hw + 0.035)), (0.02, 0.012, 0.04)), dark
    )
    builder.add(
        "mirror", box((mirror_x, mirror_y, side * (hw + 0.085)), (0.025, 0.055, 0.04)), paint
    )
    builder.add(
        "mirror",
        box((mirror_x - 0.027, mirror_y, side * (hw + 0.085)), (0.004, 0.045, 0.032)),
        glass,
    )


def _van_ends(builder: MeshBuilder, s: _VanShape) -> None:
    """Windshield, headlights, grille and bumpers at the front; window and lights at the back."""
    hl, hw = s.half_length, s.half_width
    glass, dark = rgb(30, 40, 52), rgb(24, 24, 26)
    bottom = np.array([s.windshield_x(s.belt), s.belt])
    top = np.array([s.windshield_x(s.roof), s.roof])
    up = normalize(top - bottom)
    out = np.array([up[1], -up[0]])  # the windshield's outward normal in x-y
    axes = np.column_stack([[out[0], out[1], 0.0], [up[0], up[1], 0.0], [0.0, 0.0, 1.0]])
    middle = (bottom + top) / 2.0
    half_span = np.linalg.norm(top - bottom) / 2.0
    builder.add(
        "windshield", box((*middle, 0.0), (0.008, half_span - 0.08, hw - 0.07), axes), glass
    )

    for z in (-0.29 * hw / 0.42, 0.29 * hw / 0.42):
        base = (hl - 0.01, s.belt - 0.12, z)
        builder.add(
            "headlight",
            lathe(base, (1.0, 0.0, 0.0), [(0.06, 0.0), (0.06, 0.018), (0.045, 0.028)], 20),
            rgb(255, 244, 200),
        )
        builder.add(
            "taillight",
            box_between(
                (-hl - 0.012, s.belt - 0.2, z - 0.05), (-hl + 0.01, s.belt + 0.02, z + 0.05)
            ),
            rgb(200, 20, 24),
        )
    builder.add(
        "grille",
        box_between((hl - 0.01, s.belt - 0.2, -0.17), (hl + 0.012, s.belt - 0.07, 0.17)),
        dark,
    )
    for x0, x1 in ((hl - 0.05, hl + 0.05), (-hl - 0.05, -hl + 0.05)):
        builder.add(
            "bumper",
            box_between((x0, s.floor - 0.03, -hw - 0.01), (x1, s.floor + 0.1, hw + 0.01)),
            rgb(64, 64, 68),
        )
    builder.add(
        "rear window",
        box_between(
            (-hl - 0.006, s.belt + 0.08, -hw + 0.08), (-hl + 0.01, s.roof - 0.08, hw - 0.08)
        ),
        glass,
    )


def vehicle(seed: int = 0) -> RenderMesh:
    """A delivery van, long along x (nose towards +x), standing on y = 0, centred in z.

    Its sides are vertical and carry the detail (windows, door seams, handles, a rubbing
    strip, a marker light, mirrors, wheels with spoked rims), so a reverse-perspective frustum
    looking down sees them while an orthographic top view sees only the roof, the mirrors and
    the tops of the wheels and bumpers.

    Parameters
    ----------
    seed : int
        Random seed for the paint colour and small changes of length and height.

    Returns
    -------
    RenderMesh
        Closed, flat-shaded parts (chamfered body and cabin, boxes) and smooth round parts
        (tyres, rims, hubs, headlights), each listed in ``extra["parts"]``.
    """
    rng = np.random.default_rng(seed)
    paint = rgb(*_PAINTS[int(rng.integers(len(_PAINTS)))])
    shape = _VanShape(
        half_length=0.95 * rng.uniform(0.97, 1.03),
        half_width=0.42,
        floor=0.16,
        belt=0.52,
        roof=0.9 + rng.uniform(-0.04, 0.04),
        wheel_radius=0.2,
    )
    builder = MeshBuilder()
    _van_body(builder, shape, paint)
    _van_wheels(builder, shape)
    for side in (-1.0, 1.0):
        _van_side(builder, shape, side, paint)
    _van_ends(builder, shape)
    return builder.build("vehicle")
