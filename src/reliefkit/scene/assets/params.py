"""Checks of the assets' parameters: each bad value is a `UsageError` naming the parameter."""

from __future__ import annotations

import numpy as np

from ...errors import UsageError


def check_int(label: str, value, lo: int, hi: int | None = None) -> int:
    """`value` as an int within [lo, hi], else a `UsageError`."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise UsageError(f"{label} must be an integer, got {value!r}")
    if value < lo or (hi is not None and value > hi):
        limit = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise UsageError(f"{label} must be {limit}, got {value}")
    return int(value)


def check_positive(label: str, value) -> float:
    """`value` as a positive finite float, else a `UsageError`."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise UsageError(f"{label} must be a number, got {value!r}") from None
    if not np.isfinite(x) or x <= 0:
        raise UsageError(f"{label} must be a positive finite number, got {value!r}")
    return x
