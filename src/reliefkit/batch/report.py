"""What a batch did: one record per asset, appended to ``OUT/batch.jsonl`` as it finishes,
and the summary table at the end."""

from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ..units import format_bytes

JSONL_NAME = "batch.jsonl"
STATUSES = ("ok", "skipped", "failed")  # skipped: its output already held its cache key


@dataclass(frozen=True)
class AssetRecord:
    """One asset's line in batch.jsonl (docs/batch.md lists the fields)."""

    input: str
    output: str
    kind: str
    status: str
    seconds: float = 0.0
    bytes: int = 0
    figures: tuple = ()
    warnings: tuple = ()
    error: str | None = None
    key: str | None = None

    def json_line(self) -> str:
        record = asdict(self) | {"seconds": round(self.seconds, 3),
                                 "figures": list(self.figures),
                                 "warnings": list(self.warnings)}
        return json.dumps(record, ensure_ascii=False, allow_nan=False) + "\n"


@dataclass
class BatchReport:
    """Every asset's record, in the order they finished; ``total`` assets were planned."""

    out: Path
    total: int = 0
    records: list[AssetRecord] = field(default_factory=list)
    seconds: float = 0.0
    stale_removed: int = 0       # earlier bakes' .glb and thumbnails beside rebaked assets
    wrote: tuple = ()            # files besides the outputs (sheet.png, index.html)
    notes: list[str] = field(default_factory=list)   # lines for the end of the summary

    def of(self, status: str) -> list[AssetRecord]:
        return [r for r in self.records if r.status == status]

    @property
    def ok(self) -> list[AssetRecord]:
        return self.of("ok")

    @property
    def skipped(self) -> list[AssetRecord]:
        return self.of("skipped")

    @property
    def failed(self) -> list[AssetRecord]:
        return self.of("failed")

    @property
    def exit_status(self) -> int:
        """0 when every asset is baked (skipped ones were already), 1 when any failed."""
        return 1 if self.failed else 0

    def add(self, record: AssetRecord) -> None:
        """Record ``record`` and append its line to batch.jsonl (one write, so a stopped
        batch leaves whole lines)."""
        self.records.append(record)
        fd = os.open(self.out / JSONL_NAME, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
        try:
            os.write(fd, record.json_line().encode("utf-8"))
        finally:
            os.close(fd)

    def summary(self) -> list[str]:
        """The table printed at the end, then one line per failed asset."""
        lines = [f"{'status':<8} {'assets':>7} {'seconds':>9} {'written':>11}"]
        for status in STATUSES:
            records = self.of(status)
            seconds = f"{sum(r.seconds for r in records):.1f}" if status != "skipped" else "-"
            written = format_bytes(sum(r.bytes for r in records)) if status == "ok" else "-"
            lines.append(f"{status:<8} {len(records):>7} {seconds:>9} {written:>11}")
        baked = len(self.ok)
        rate = f", {3600 * baked / self.seconds:.0f} baked per hour" if baked and self.seconds \
            else ""
        lines.append(f"{len(self.records)} of {self.total} assets in {self.seconds:.1f} s"
                     f"{rate}")
        lines += [f"failed: {r.error}" for r in self.failed]
        if self.stale_removed:
            lines.append(f"removed {self.stale_removed} file(s) an earlier bake left beside "
                         "assets baked now (.glb, thumbnails: they showed the old bake)")
        lines += [f"wrote {path}" for path in self.wrote] + self.notes
        return lines


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a batch: the workers are stopped, every output written is whole, and
    ``report`` holds what was done (a rerun goes on from there)."""

    def __init__(self, report: BatchReport) -> None:
        super().__init__()
        self.report = report
