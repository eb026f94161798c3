"""GPU timer queries for benchmarks (never for assertions in tests)."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence


def gpu_times_ms(ctx, draws: Sequence[Callable[[], None]], *, repeats: int = 5,
                 warmup: int = 1) -> list[dict]:
    """Time each draw with GL_TIME_ELAPSED queries and wall clock; medians in milliseconds.

    The draws are interleaved: each of the ``repeats`` rounds times every draw once, so a
    slow drift of the machine lands on all of them alike and their ratios are steadier than
    those of timings taken one after the other. Wall time includes ``ctx.finish()`` so it is
    meaningful on software rasterizers, whose timer queries may only measure command
    submission.
    """
    for _ in range(warmup):
        for draw in draws:
            draw()
    ctx.finish()
    gpu = [[] for _ in draws]
    wall = [[] for _ in draws]
    for _ in range(max(1, repeats)):
        for k, draw in enumerate(draws):
            query = ctx.query(time=True)
            start = time.perf_counter()
            with query:
                draw()
            ctx.finish()
            wall[k].append((time.perf_counter() - start) * 1e3)
            gpu[k].append(query.elapsed / 1e6)
    return [{"gpu_ms": statistics.median(g), "wall_ms": statistics.median(w),
             "repeats": len(w)} for g, w in zip(gpu, wall, strict=True)]
