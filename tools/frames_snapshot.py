"""Save (or compare) the Frames of every technique's samples, for refactors that must not
change a pixel.

    python tools/frames_snapshot.py save DIR      # one .npz per sample and option set
    python tools/frames_snapshot.py compare DIR   # bit-compare against a saved DIR
    python tools/frames_snapshot.py compare DIR relief:   # only names starting so

Each sample is drawn from three views at 64x48 with its default options, with every choice
of every declared option changed one at a time (so each code path of each drawable is
drawn at least once), and once instrumented; the mesh (a textured demo asset) too. Saved:
colour, mask, depth, position, normal, the iteration counts and the JSON of `stats`
(timings dropped).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

VIEWS = [(30.0, 35.0, 2.4), (200.0, 10.0, 2.0), (110.0, -25.0, 2.6)]
SIZE = (64, 48)
TIMING_KEYS = ("seconds", "ms", "time")


def _samples() -> dict:
    from reliefkit.builtins import registry
    from reliefkit.io.inputs import load_mesh

    out = {"mesh:cup": load_mesh("demo:cup")}
    for tech in registry().techniques():
        for kind, rep in tech.samples().items():
            out[f"{tech.name}:{kind}"] = rep
    return out


def _option_sets(rep) -> list[tuple[str, dict]]:
    """The defaults, every other value of each option alone, and every pair of them."""
    from reliefkit.render import render_options

    values = []
    for opt in render_options(rep):
        if opt.name == "time":
            values.append([("time", 0.25)])
        elif opt.kind == "bool":
            values.append([(opt.name, not opt.default)])
        elif opt.choices:
            values.append([(opt.name, c) for c in opt.choices if c != opt.default])
    sets = [("default", {})]
    for i, first in enumerate(values):
        for a in first:
            sets.append((f"{a[0]}={a[1]}", dict([a])))
            for second in values[i + 1:]:
                sets += [(f"{a[0]}={a[1]},{b[0]}={b[1]}", dict([a, b])) for b in second]
    return sets


def _frames(only: str = ""):
    """(name, arrays) for every sample, option set and view whose name starts with
    ``only``; failures recorded as such."""
    from reliefkit.render import render
    from reliefkit.scene.views import orbit_bounds

    samples = _samples()
    if "list:".startswith(only) or only.startswith("list:"):
        yield from _list_frames(samples)
    for sample_name, rep in samples.items():
        if not sample_name.startswith(only) and not only.startswith(sample_name):
            continue
        for set_name, options in _option_sets(rep):
            for counted in (False, True) if set_name == "default" else (False,):
                for v, view in enumerate(VIEWS):
                    name = f"{sample_name}|{set_name}{'|counted' if counted else ''}|v{v}"
                    camera = orbit_bounds(rep.bounds, *view, size=SIZE)
                    try:
                        frame = render(rep, camera, count_iterations=counted, **options)
                    except Exception as exc:  # an option the sample refuses is recorded
                        yield name, {"error": np.array(f"{type(exc).__name__}: {exc}")}
                        continue
                    stats = {k: v for k, v in frame.stats.items()
                             if not any(t in k for t in TIMING_KEYS)}
                    arrays = {"color": frame.color, "mask": frame.mask, "depth": frame.depth,
                              "position": frame.position, "normal": frame.normal,
                              "stats": np.array(json.dumps(stats, sort_keys=True,
                                                           default=str))}
                    if "iterations" in frame.extra:
                        arrays["iterations"] = frame.extra["iterations"]
                    yield name, arrays


def _list_frames(samples):
    """A transparent shell in front of an opaque relief, drawn as one list (the passes)."""
    from reliefkit.render import render
    from reliefkit.scene.views import orbit_bounds

    shell, relief = samples["shellvolume:shell-volume"], samples["relief:relief"]
    lo = np.minimum(shell.bounds[0], relief.bounds[0])
    hi = np.maximum(shell.bounds[1], relief.bounds[1])
    for v, view in enumerate(VIEWS):
        frame = render([relief, shell], orbit_bounds((lo, hi), *view, size=SIZE))
        yield f"list:relief+shell|default|v{v}", {
            "color": frame.color, "mask": frame.mask, "depth": frame.depth,
            "position": frame.position, "normal": frame.normal}


def _file(folder: Path, name: str) -> Path:
    return folder / (name.replace("|", "__").replace(":", "_").replace("=", "-") + ".npz")


def save(folder: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    count = 0
    for name, arrays in _frames():
        np.savez_compressed(_file(folder, name), **arrays)
        count += 1
    print(f"saved {count} frames to {folder}")


def compare(folder: Path, only: str = "") -> int:
    differ, same, missing = [], 0, []
    seen = set()
    for name, arrays in _frames(only):
        path = _file(folder, name)
        seen.add(path.name)
        if not path.exists():
            missing.append(name)
            continue
        with np.load(path) as old:
            keys = sorted(set(old.files) | set(arrays))
            bad = [k for k in keys if k not in old.files or k not in arrays
                   or not np.array_equal(old[k], arrays[k], equal_nan=old[k].dtype.kind == "f")]
        if bad:
            differ.append(f"{name}: {', '.join(bad)}")
        else:
            same += 1
    prefix = _file(folder, only).name[:-len(".npz")]
    gone = sorted(p.name for p in folder.glob(prefix + "*.npz") if p.name not in seen)
    print(f"{same} identical, {len(differ)} differ, {len(missing)} new, {len(gone)} gone")
    for line in differ + [f"new: {m}" for m in missing] + [f"gone: {g}" for g in gone]:
        print("  " + line)
    return 1 if differ or gone else 0


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4) or sys.argv[1] not in ("save", "compare"):
        sys.exit(__doc__)
    command, folder = sys.argv[1], Path(sys.argv[2])
    sys.exit(save(folder) if command == "save" else
             compare(folder, sys.argv[3] if len(sys.argv) == 4 else ""))
