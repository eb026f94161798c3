"""Each representation sized to a byte budget: the arguments, the candidates and the search.

Every baker that declares a `core.technique.Sizing` stands in for a whole mesh; its one
resolution knob ``n`` is searched so that what the written .rk file puts on the GPU fits the
budget: its arrays read back from the file as a GPU holds them (block-compressed textures
with their mip chains, `compact.compact.gpu_bytes`), never predicted, so that it is the
measure the decimated mesh is held to (`scene.decimate.gpu_bytes`, compact). The file's own
size (deflated: the download) is reported beside it. The search is deterministic: from the
knob's lowest value it steps up by the growth the last two probes measured (at most
doubling ``n``, so a probe overshoots a budget by a bounded factor) until a probe no longer
fits, then bisects between the largest ``n`` that fits and the smallest that does not,
until they are within `KNOB_TOLERANCE` of each other. Every probe is kept, so the budgets
of one run share them.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..bake import bake
from ..compact.compact import gpu_bytes
from ..core.technique import bakers
from ..errors import ReliefkitError, UsageError
from ..io.rk import load, save
from ..units import parse_bytes

#: The options every shootout bake gets besides its knob (the one place to change them all):
#: block-compressed textures and 16-bit heights, as an engine ships them.
BAKE_OPTIONS: dict = {"compress": "bc"}

BUDGET_RANGE = (2**10, 2**28)  # 1 KiB .. 256 MiB: a larger bake would not fit this machine
SIZE_RANGE = (16, 2048)        # screen sizes in pixels
KNOB_TOLERANCE = 0.05          # the search stops when the bracket is within 5% of the knob
MAX_GROWTH = 2.0               # a step up at most doubles the knob


def parse_budgets(text: str) -> list[int]:
    """``1MB,4MB,16MB`` -> byte counts, ascending and distinct (KB, MB, GB are binary:
    1 MB = 2^20 bytes; KiB, MiB, GiB mean the same; a bare number is bytes)."""
    out = set()
    for item in str(text).split(","):
        value = parse_bytes(item)
        if value is None:
            raise UsageError(f"--budgets {text}: '{item.strip()}' is no byte count (give e.g. "
                             "64KB,1MB,16MB)")
        lo, hi = BUDGET_RANGE
        if not lo <= value <= hi:
            raise UsageError(f"--budgets {text}: '{item.strip()}' is outside 1KB..256MB")
        out.add(value)
    return sorted(out)


def parse_sizes(text: str) -> list[int]:
    """``64,256,1024`` -> screen sizes in pixels (the bounding sphere's diameter), ascending."""
    out = set()
    for item in str(text).split(","):
        lo, hi = SIZE_RANGE
        if not item.strip().isdigit() or not lo <= int(item) <= hi:
            raise UsageError(f"--sizes {text}: '{item.strip()}' is no size in pixels from "
                             f"{lo} to {hi}")
        out.add(int(item))
    return sorted(out)


@dataclass(frozen=True)
class Candidate:
    """One row of the shootout: a baker and one of its sizings."""

    label: str
    kind: str
    sizing: object


def candidates(kinds: list[str] | None = None) -> list[Candidate]:
    """Every registered sizing (the registry decides what joins), or those whose label or
    baker is named in ``kinds``; an unknown name is refused with the known ones."""
    every = [Candidate(s.label or name, name, s) for name, (_, b) in bakers().items()
             for s in b.sizings]
    if kinds is None:
        return every
    known = {c.label for c in every} | {c.kind for c in every}
    unknown = [k for k in kinds if k not in known]
    not_sized = [k for k in unknown if k in unsized()]
    if not_sized:
        raise UsageError(f"--kinds: {', '.join(not_sized)} cannot be sized to a budget (it "
                         f"does not stand in for a whole mesh); the shootout's kinds: "
                         f"{', '.join(sorted(known))}")
    if unknown:
        raise UsageError(f"--kinds: unknown {', '.join(unknown)} (known: "
                         f"{', '.join(sorted(known))})")
    return [c for c in every if c.label in kinds or c.kind in kinds]


def unsized() -> list[str]:
    """The bakers of meshes that declare no sizing: not in the shootout (the report names
    them, so a new kind without one is seen missing)."""
    return [name for name, (_, b) in bakers().items() if "mesh" in b.sources and not b.sizings]


def parse_kinds(text: str | None) -> list[Candidate]:
    """``--kinds a,b`` (None: every candidate)."""
    if text is None:
        return candidates()
    return candidates([k.strip() for k in text.split(",") if k.strip()])


def unfit_reason(candidate: Candidate, mesh) -> str | None:
    """Why ``candidate`` cannot represent ``mesh`` at all (None: it can)."""
    if candidate.sizing.needs_uvs and mesh.uvs is None:
        return "needs a mesh with texture coordinates (uvs)"
    return None


def file_gpu_bytes(path) -> int:
    """Bytes a GPU holds for the representation in the .rk file at ``path``, read back."""
    return sum(on_gpu for _, on_gpu, _ in gpu_bytes(load(path)).values())


@dataclass
class Probe:
    n: int
    bytes: int | None = None       # on the GPU, read from the file; None: the bake was refused
    bake_s: float = 0.0
    path: Path | None = None
    error: str | None = None
    file_bytes: int | None = None  # the file's size on disk


@dataclass
class Search:
    """The probes of one candidate on one mesh, shared by every budget."""

    candidate: Candidate
    mesh: object
    folder: Path
    probes: dict[int, Probe] = field(default_factory=dict)

    def probe(self, n: int) -> Probe:
        if n not in self.probes:
            self.probes[n] = self._bake(n)
        return self.probes[n]

    def _bake(self, n: int) -> Probe:
        sizing = self.candidate.sizing
        params = {**sizing.params(n, self.mesh), **BAKE_OPTIONS}
        path = self.folder / f"{self.candidate.label}-n{n}.rk"
        start = time.perf_counter()
        try:
            rep = bake(self.mesh, self.candidate.kind, **params)
        except ReliefkitError as error:  # the baker refuses this size: it does not fit
            return Probe(n, error=str(error))
        seconds = time.perf_counter() - start
        save(path, rep)
        return Probe(n, file_gpu_bytes(path), seconds, path, file_bytes=path.stat().st_size)

    def fits(self, n: int, budget: int) -> bool:
        found = self.probe(n)
        return found.bytes is not None and found.bytes <= budget

    def largest_fitting(self, budget: int) -> Probe | None:
        """The probe of the largest knob value found whose file fits ``budget`` (None: not
        even the smallest does)."""
        lo, hi = self.candidate.sizing.lo, self.candidate.sizing.hi
        if not self.fits(lo, budget):
            return None
        below, above = lo, None
        while above is None and below < hi:
            step = self._next_up(below, budget)
            if self.fits(step, budget):
                below = step
            else:
                above = step
        while above is not None and above - below > max(1, KNOB_TOLERANCE * below):
            mid = round(math.sqrt(below * above))
            mid = min(max(mid, below + 1), above - 1)
            if self.fits(mid, budget):
                below = mid
            else:
                above = mid
        return self.probe(below)

    def _next_up(self, n: int, budget: int) -> int:
        """The next knob value to try above ``n`` (which fits): a tolerance beyond where the
        growth measured between the last two probes predicts ``budget`` (so the next probe
        most likely brackets it), at least a tolerance above ``n``, at most doubled."""
        hi = self.candidate.sizing.hi
        known = sorted(k for k, p in self.probes.items() if p.bytes is not None and k <= n)
        factor = MAX_GROWTH
        if len(known) >= 2:
            a, b = self.probes[known[-2]], self.probes[known[-1]]
            growth = math.log(b.bytes / a.bytes) / math.log(b.n / a.n) if b.bytes > a.bytes \
                else 0.0
            if growth > 0:
                predicted = (budget / b.bytes) ** (1.0 / growth) * (1 + KNOB_TOLERANCE)
                factor = min(MAX_GROWTH, max(1 + KNOB_TOLERANCE, predicted))
        return min(hi, max(n + 1, math.floor(n * factor)))

    def measured(self) -> list[list[int]]:
        """[n, bytes on the GPU] of every probe so far that baked, by n."""
        return [[n, p.bytes] for n, p in sorted(self.probes.items()) if p.bytes is not None]

    def failure(self) -> str:
        """Why no knob value fits (for the report's row)."""
        lo = self.probe(self.candidate.sizing.lo)
        if lo.error:
            return f"the bake at its smallest ({lo.n}) was refused: {lo.error}"
        return f"at its smallest ({self.candidate.sizing.knob}: {lo.n}) it takes " \
               f"{lo.bytes:,} bytes on the GPU"
