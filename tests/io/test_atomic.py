"""The atomic writer under hostile names and failing writes: short temp names, errors that
name the user's path (never the hidden temp file), and no temp file left behind."""

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from reliefkit.errors import FormatError, UsageError
from reliefkit.io.atomic import TEMP_NAME_BYTES, atomic_path, check_writable, temp_prefix


def listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize("length", [200, 240, 250])
def test_a_long_valid_name_is_written(tmp_path, length):
    dest = tmp_path / ("n" * (length - 4) + ".png")
    assert len(dest.name) == length
    seen = []
    with atomic_path(dest) as tmp:
        seen.append(tmp)
        tmp.write_bytes(b"data")
    assert dest.read_bytes() == b"data" and listing(tmp_path) == [dest.name]
    name = seen[0].name
    assert len(name) <= 1 + TEMP_NAME_BYTES + 1 + 8 + 4 and name.endswith(".tmp")
    assert seen[0].parent == dest.parent  # beside the destination: one file system


def test_temp_prefix_is_bounded_in_bytes_and_never_splits_a_character():
    assert temp_prefix("x.rk") == ".x.rk."
    long = temp_prefix("é" * 200 + ".png")
    assert len(os.fsencode(long)) <= TEMP_NAME_BYTES + 2 and long == "." + "é" * 20 + "."


def test_a_directory_in_the_way_is_named_not_the_temp_file(tmp_path):
    (tmp_path / "x.png").mkdir()
    with pytest.raises(UsageError) as info, atomic_path(tmp_path / "x.png") as tmp:
        tmp.write_bytes(b"data")
    message = str(info.value)
    assert "x.png" in message and ".tmp" not in message and "directory" in message
    assert listing(tmp_path) == ["x.png"]


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EFBIG, errno.EISDIR])
@pytest.mark.parametrize("where", ["write", "replace"])
def test_os_errors_name_the_users_path_and_leave_nothing(tmp_path, monkeypatch, code, where):
    dest = tmp_path / "out.npz"
    dest.write_bytes(b"old")

    def fail(*args, **kwargs):
        raise OSError(code, os.strerror(code), str(tmp_path / ".out.npz.abcd1234.tmp"))

    if where == "replace":
        monkeypatch.setattr(os, "replace", fail)
    with pytest.raises(FormatError) as info, atomic_path(dest, error=FormatError) as tmp:
        tmp.write_bytes(b"new")
        if where == "write":
            fail()
    message = str(info.value)
    assert str(dest) in message and os.strerror(code) in message, message
    assert ".tmp" not in message and "abcd" not in message
    assert dest.read_bytes() == b"old" and listing(tmp_path) == ["out.npz"]


def test_check_writable_refuses_before_any_work(tmp_path, monkeypatch):
    with pytest.raises(UsageError, match=r"--aovs .*missing.*does not exist"):
        check_writable(tmp_path / "missing" / "a.npz", "--aovs")
    (tmp_path / "d.npz").mkdir()
    with pytest.raises(UsageError, match="is a directory"):
        check_writable(tmp_path / "d.npz", "--aovs")
    (tmp_path / "file").write_text("")
    with pytest.raises(UsageError, match="not a folder"):
        check_writable(tmp_path / "file" / "a.npz", "--aovs")
    with pytest.raises(UsageError, match="exists and is not a folder"):
        check_writable(tmp_path / "file", "--out", folder=True)
    assert check_writable(tmp_path / "new" / "deeper", "--out", folder=True)  # made later
    real_access = os.access
    monkeypatch.setattr(os, "access", lambda p, mode: False if Path(p) == tmp_path
                        else real_access(p, mode))
    with pytest.raises(UsageError, match="not writable"):
        check_writable(tmp_path / "a.npz", "--aovs")
    with pytest.raises(UsageError, match="not writable"):
        check_writable(tmp_path / "new", "--out", folder=True)


def test_a_file_size_limit_is_one_line_naming_the_output(tmp_path):
    """RLIMIT_FSIZE: the write fails with EFBIG (Python ignores SIGXFSZ)."""
    resource = pytest.importorskip("resource")

    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (32 * 1024, 32 * 1024))

    out = tmp_path / ("big" * 30 + ".png")
    # a 400x400 random picture is far above the 32 KiB limit
    code = ("import sys, numpy as np\nfrom PIL import Image\n"
            "from reliefkit.pictures import save_image\n"
            "from reliefkit.errors import ReliefkitError\n"
            "img = Image.fromarray(np.random.default_rng(0).integers(0, 255, (400, 400, 3), "
            "dtype=np.uint8))\n"
            "try:\n    save_image(img, sys.argv[1])\n"
            "except ReliefkitError as exc:\n    print(exc, file=sys.stderr); sys.exit(1)\n")
    result = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True,
                            text=True, timeout=120, preexec_fn=limit)
    assert result.returncode == 1, result.stderr
    assert "File too large" in result.stderr and out.name in result.stderr
    assert ".tmp" not in result.stderr
    assert listing(tmp_path) == []


def test_sigterm_during_a_write_removes_the_temp_file(gl, tmp_path):
    """A big compressed AOV file is being written when SIGTERM arrives: the CLI's handler
    unwinds through `atomic_path`, which removes its temp file; exit status 143."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "reliefkit.cli", "render", "demo:blob",
                             "--size", "3000x3000", "-o", str(tmp_path / "b.png"), "--aovs",
                             str(tmp_path / "b.npz")], cwd=tmp_path, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 240
    sent = False
    while time.monotonic() < deadline and proc.poll() is None:
        if any(name.startswith(".b.npz.") and name.endswith(".tmp")
               for name in os.listdir(tmp_path)):
            time.sleep(0.2)  # well inside the write
            proc.send_signal(signal.SIGTERM)
            sent = True
            break
        time.sleep(0.01)
    out, err = proc.communicate(timeout=120)
    if not sent:
        pytest.skip(f"the write finished before SIGTERM could be sent (rc {proc.returncode})")
    if proc.returncode == 0:
        pytest.skip("the write finished between the check and the signal")
    assert proc.returncode == 143, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: terminated"), err
    assert not [n for n in os.listdir(tmp_path) if n.endswith(".tmp")], os.listdir(tmp_path)
    assert "b.npz" not in os.listdir(tmp_path)


def test_outputs_written_together_appear_all_or_none(tmp_path):
    from reliefkit.io.atomic import written_together

    old = tmp_path / "a.png"
    old.write_bytes(b"old")
    full = pytest.raises(UsageError, match="cannot write .*b.npz: No space left")
    with full, written_together():
        with atomic_path(old) as tmp:
            tmp.write_bytes(b"new")
        with atomic_path(tmp_path / "b.npz"):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    assert listing(tmp_path) == ["a.png"] and old.read_bytes() == b"old"
    with pytest.raises(KeyboardInterrupt), written_together():
        with atomic_path(old) as tmp:
            tmp.write_bytes(b"new")
        raise KeyboardInterrupt
    assert listing(tmp_path) == ["a.png"] and old.read_bytes() == b"old"
    with written_together():
        for name in ("a.png", "b.npz"):
            with atomic_path(tmp_path / name) as tmp:
                tmp.write_bytes(name.encode())
        assert old.read_bytes() == b"old"  # nothing moved before the group's end
    assert [(tmp_path / n).read_bytes() for n in listing(tmp_path)] == [b"a.png", b"b.npz"]
