"""What every bench report shares: the machine it ran on, and writing its json, markdown and
plots."""

from __future__ import annotations

import json
import os
import platform
from collections.abc import Callable
from pathlib import Path

from ..io.atomic import atomic_path


def machine() -> dict:
    """Platform, CPU and the GL renderer (or why there is none), for the report's header."""
    info = {"platform": platform.platform(), "cpu": platform.processor() or platform.machine(),
            "cpus": os.cpu_count(), "python": platform.python_version(),
            "renderer": "unavailable", "gl": "unavailable"}
    try:
        from ..gl.context import gl_info

        gl = gl_info()
        info |= {"renderer": gl.get("renderer"), "gl": gl.get("version")}
    except Exception as error:  # no GL context: say so instead of failing the report
        info["renderer"] = f"unavailable ({type(error).__name__}: {error})"
    return info


def machine_line(m: dict) -> str:
    return (f"Machine: {m['renderer']}, {m['gl']}, {m['platform']}, CPU {m['cpu']} x "
            f"{m['cpus']}, Python {m['python']}.")


def write_report(out, stem: str, data: dict, markdown: Callable[[dict], str]) -> list[Path]:
    """``stem``.json (the data) and ``stem``.md (``markdown(data)``) into ``out``, atomically."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{stem}.json", out / f"{stem}.md"]
    with atomic_path(paths[0]) as tmp:
        tmp.write_text(json.dumps(data, indent=2))
    with atomic_path(paths[1]) as tmp:
        tmp.write_text(markdown(data))
    return paths


def save_figure(fig, path) -> None:
    """A matplotlib figure as a PNG at ``path``, atomically (no torn file), then closed."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    with atomic_path(Path(path)) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
