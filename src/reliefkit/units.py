"""Numbers for people: byte counts with binary units."""

from __future__ import annotations


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
