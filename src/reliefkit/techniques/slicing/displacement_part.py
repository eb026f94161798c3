"""The displacement-mapping half of the slicing technique (§3): filled in by the displacement
modules (see `parts.Part`)."""

from __future__ import annotations

from .parts import Part

PART = Part()
