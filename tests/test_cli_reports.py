"""What the command line says: help that names every owner and asset, a bake's summary line,
an output name that points to the flag it needs."""

import re
from pathlib import Path

from helpers import run_cli

WIDE = {"COLUMNS": "400"}  # argparse wraps help at the terminal's width


def flag_help(help_text: str, flag: str) -> str:
    """The help of ``flag`` in ``--help`` output, its wrapped lines joined."""
    lines = help_text.splitlines()
    start = next(k for k, line in enumerate(lines) if line.strip().startswith(flag))
    text = [lines[start].strip()[len(flag):]]
    for line in lines[start + 1:]:
        if not line.strip() or line.strip().startswith("-"):
            break
        text.append(line.strip())
    return " ".join(" ".join(text).split())


def test_render_help_names_each_owner_once():
    """--unlit is declared by the shell volume, the depth objects and the displacement maps:
    the two halves of the slicing technique are named apart, each owner once."""
    out = run_cli("render", "--help", env=WIDE)
    assert out.returncode == 0, out.stderr
    text = flag_help(out.stdout, "--unlit, --no-unlit")
    owners = re.findall(r"(?:^|; )([\w/-]+): ", text)
    assert len(owners) == len(set(owners)) == 3, text
    assert "depth-object/visual-hull" in owners and "displacement" in owners, owners


def test_top_level_help_lists_every_demo_asset():
    """The help lists exactly the registered assets, every demo:NAME its own examples use is
    among them, and every listed asset builds."""
    from reliefkit.scene.assets import DEMO_NAMES, make_asset

    out = run_cli("--help")
    assert out.returncode == 0, out.stderr
    text = " ".join(out.stdout.split())
    listed = re.search(r"\(demo assets: ([^)]*)\)", text).group(1).split(", ")
    assert listed == list(DEMO_NAMES)
    used = set(re.findall(r"demo:([\w-]+)", text)) - {"NAME"}
    assert used and used <= set(listed), used - set(listed)
    for name in listed:
        assert make_asset(name).triangle_count > 0, name


def test_cli_doc_lists_every_demo_asset():
    """docs/cli.md's paragraph on demo:NAME names every registered asset and no other."""
    from reliefkit.scene.assets import DEMO_NAMES

    doc = (Path(__file__).parents[1] / "docs" / "cli.md").read_text()
    paragraph = re.search(r"`demo:NAME` for a procedural asset:(.*?)\(`reliefkit --help`",
                          doc, re.S).group(1)
    assert re.findall(r"`([\w-]+)`", paragraph) == list(DEMO_NAMES)


def test_bake_summarises_its_arrays(gl, tmp_path):
    """A cube's 25 arrays are one short line: their count and total as the file holds them,
    and only the three largest by name."""
    import zipfile

    import numpy as np

    out = run_cli("bake", "demo:blob", "--as", "relief-cube", "--depth-res", "16",
                  "--no-safety", "-o", tmp_path / "cube.rk")
    assert out.returncode == 0, out.stderr
    with zipfile.ZipFile(tmp_path / "cube.rk") as rk:
        sizes = {}
        for member in rk.namelist():
            if member.endswith(".npy"):
                with rk.open(member) as f:
                    sizes[member[:-4]] = np.load(f, allow_pickle=False).nbytes
    line = next(x for x in out.stdout.splitlines() if x.startswith("wrote "))
    assert f": {len(sizes)} arrays, " in line, line
    named = [name for name in sizes if re.search(rf"\b{name}\b", line)]
    assert len(named) == 3, line
    assert sorted(sizes[n] for n in named) == sorted(sizes.values())[-3:], line
