"""GPU timer queries for benchmarks (never for assertions in tests)."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable


def gpu_time_ms(ctx, draw: Callable[[], None], *, repeats: int = 5, warmup: int = 1) -> dict:
    """Time ``draw`` with GL_TIME_ELAPSED queries and wall clock; medians in milliseconds.

    Wall time includes ``ctx.finish()`` so it is meaningful on software rasterizers, whose
    timer queries may only measure command submission.
    """
    for _ in range(warmup):
        draw()
    ctx.finish()
    gpu, wall = [], []
    for _ in range(max(1, repeats)):
        query = ctx.query(time=True)
        start = time.perf_counter()
        with query:
            draw()
        ctx.finish()
        wall.append((time.perf_counter() - start) * 1e3)
        gpu.append(query.elapsed / 1e6)
    return {"gpu_ms": statistics.median(gpu), "wall_ms": statistics.median(wall),
            "repeats": len(wall)}
