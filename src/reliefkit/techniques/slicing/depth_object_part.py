"""The depth-object and visual-hull half of the slicing technique (§4, §5)."""

from __future__ import annotations

from .parts import Part

PART = Part()
