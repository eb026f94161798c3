"""Progress: a rich bar on a terminal, plain rate-limited lines anywhere else."""

from __future__ import annotations

import io

import pytest

from reliefkit import progress
from reliefkit.progress import activity, progress_bar


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_plain_lines_every_interval_and_a_final_one():
    stream = io.StringIO()
    with progress_bar("demo", 3, stream=stream, interval=0.0) as advance:
        for k in range(3):
            advance(k + 1)
    lines = stream.getvalue().splitlines()
    assert lines[:2] == ["demo: 1/3", "demo: 2/3"]
    assert lines[2].startswith("demo: 3/3, done in ") and len(lines) == 3


def test_plain_lines_are_rate_limited():
    stream = io.StringIO()
    with progress_bar("bake", 10, stream=stream, interval=3600.0) as advance:
        for k in range(10):
            advance(k + 1)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 1 and lines[0].startswith("bake: 10/10, done in ")


def test_plain_lines_say_the_time_left_at_the_rate_after_the_start_up(monkeypatch):
    """The first item's time holds the start-up (a batch's workers starting: 27 s for the
    first of 23 assets, then 2 s each): 'eta 614 s' for a 67 s run. The rate is taken from
    the first item done on, and nothing is guessed before there is one."""
    clock = iter([0.0, 30.0, 32.0, 36.0, 40.0])  # start; each advance; finish
    monkeypatch.setattr(progress.time, "monotonic", lambda: next(clock))
    stream = io.StringIO()
    with progress_bar("batch", 6, stream=stream, interval=0.0, eta=True) as advance:
        advance(1)  # 30 s for the first: no rate yet
        advance(2)  # 2 s for the next: 4 left, 8 s
        advance(4)  # 6 s for 3 since the first: 2 left, 4 s
    assert stream.getvalue().splitlines()[:3] == ["batch: 1/6", "batch: 2/6, eta 8 s",
                                                  "batch: 4/6, eta 4 s"]


def test_a_terminal_bar_can_say_the_time_left():
    stream = Terminal()
    with progress_bar("batch", 4, stream=stream, eta=True) as advance:
        advance(4)
    assert "eta" in stream.getvalue()


def test_a_total_given_while_running_is_used():
    stream = io.StringIO()
    with progress_bar("baking", 1, stream=stream, interval=0.0) as advance:
        advance(5, 40)
    assert stream.getvalue().splitlines()[0] == "baking: 5/40"


def test_no_final_line_when_the_work_fails():
    stream = io.StringIO()
    with pytest.raises(RuntimeError), progress_bar("demo", 2, stream=stream) as advance:
        advance(1)
        raise RuntimeError("boom")
    assert "done" not in stream.getvalue()


def test_disabled_writes_nothing():
    stream = io.StringIO()
    with progress_bar("demo", 2, stream=stream, enabled=False) as advance:
        advance(2)
    assert stream.getvalue() == ""


def test_a_terminal_gets_a_bar():
    stream = Terminal()
    with progress_bar("demo", 4, stream=stream) as advance:
        advance(4)
    text = stream.getvalue()
    assert "demo" in text and "4/4" in text and "done in" not in text


def test_activity_lines_are_prefixed():
    stream = io.StringIO()
    with activity("bench toy", stream=stream) as log:
        log("table 1: 4 ms")
    lines = stream.getvalue().splitlines()
    assert lines[0] == "bench toy: table 1: 4 ms"
    assert lines[1].startswith("bench toy: done in ")


def test_bench_reports_its_steps_as_progress(toy_bench, tmp_path, capsys):
    from reliefkit.bench import run_suite

    report, _ = run_suite("toy", out=tmp_path)
    err = capsys.readouterr().err.splitlines()
    assert "bench toy: toy bench ran" in err and err[-1].startswith("bench toy: done in ")
    assert "toy bench" in report


@pytest.fixture
def toy_bench():
    from helpers import toy_technique

    with toy_technique():
        yield


def _until_shown(stream, text: str) -> None:
    """Block like a long render until ``text`` was written (no timing assumed)."""
    import time

    while text not in stream.getvalue():
        time.sleep(0.01)


def test_a_long_single_call_shows_its_time_and_a_final_line():
    from reliefkit.progress import waiting

    stream = io.StringIO()
    with waiting("render", stream=stream, after=0.0, interval=0.0):
        _until_shown(stream, "\nrender: ")  # at least two lines of elapsed time
    lines = stream.getvalue().splitlines()
    assert len(lines) >= 3 and all(line.startswith("render: ") for line in lines)
    assert [line.endswith(" s") and "done" not in line for line in lines[:-1]] == \
        [True] * (len(lines) - 1)
    assert lines[-1].startswith("render: done in ")


def test_a_short_single_call_prints_nothing():
    from reliefkit.progress import waiting

    stream = io.StringIO()
    with waiting("render", stream=stream, after=3600.0):
        pass
    assert stream.getvalue() == ""


def test_a_long_single_call_on_a_terminal_shows_a_spinner():
    from reliefkit.progress import waiting

    stream = Terminal()
    with waiting("render", stream=stream, after=0.0):
        _until_shown(stream, "render: ")
    assert "render: done in " in stream.getvalue().splitlines()[-1]  # after the spinner
