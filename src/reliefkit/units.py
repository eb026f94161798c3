"""Numbers for people: byte counts with binary units, written and read."""

from __future__ import annotations

import re

#: What `parse_bytes` reads: KB, MB, GB are binary (1 MB = 2^20 bytes), as KiB, MiB, GiB.
UNITS = {"": 1, "B": 1, "KB": 2**10, "KIB": 2**10, "MB": 2**20, "MIB": 2**20,
         "GB": 2**30, "GIB": 2**30}


def format_bytes(n: int) -> str:
    """1536 -> '1.5 KiB', 3 * 2**20 -> '3.0 MiB'."""
    if n < 1024:
        return f"{int(n)} B"
    value = float(n)
    for unit in ("KiB", "MiB", "GiB", "TiB"):
        value /= 1024
        if value < 1024 or unit == "TiB":
            break
    return f"{value:.1f} {unit}"


def parse_bytes(text: str) -> int | None:
    """``'1.5MB'`` -> 1572864 (`UNITS`; a bare number is bytes); None for anything else."""
    match = re.fullmatch(r"\s*(\d+(?:\.\d+)?)\s*([A-Za-z]*)\s*", str(text))
    unit = match.group(2).upper() if match else None
    if match is None or unit not in UNITS:
        return None
    return int(float(match.group(1)) * UNITS[unit])
