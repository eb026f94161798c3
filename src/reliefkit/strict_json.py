"""JSON that strict parsers read: NaN and infinities, which Python's json writes as bare
NaN/Infinity tokens, become null (a forged file's params, a PSNR of identical images)."""

from __future__ import annotations

import json
import math


def finite_or_null(value):
    """``value`` with every NaN and infinity, at any depth of dicts and lists, as None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: finite_or_null(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [finite_or_null(item) for item in value]
    return value


def dumps(value, **kwargs) -> str:
    """`json.dumps` of `finite_or_null(value)`, refusing anything else non-finite."""
    return json.dumps(finite_or_null(value), allow_nan=False, **kwargs)
