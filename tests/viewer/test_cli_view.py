"""`reliefkit view`: serves on 127.0.0.1 and stops on Ctrl-C, the page's POSTs reach its
log; --export-html writes a folder that Python's static server shows; bad input is one
line."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
import urllib.request

from browser import canvas_rgba, chromium, messages, open_page, state
from helpers import assert_one_line_error, run_cli

TIMEOUT_S = 300


def _first_line(process) -> str:
    return process.stdout.readline().strip()


def test_view_serves_until_ctrl_c_and_logs_what_the_page_posts(gl):
    process = subprocess.Popen([sys.executable, "-m", "reliefkit.cli", "view", "demo:cup",
                                "--no-browser"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    try:
        line = _first_line(process)
        assert line.startswith("serving http://127.0.0.1:") and line.endswith("(Ctrl-C stops)")
        url = line.split()[1]
        with urllib.request.urlopen(url) as response:
            assert b'src="viewer.js"' in response.read()
        with urllib.request.urlopen(url + "inputs.json") as response:
            assert b'"kind": "mesh"' in response.read()
        request = urllib.request.Request(url + "log", data=b"error: a test\nline", method="POST")
        with urllib.request.urlopen(request) as response:
            assert response.status == 204
        process.send_signal(signal.SIGINT)
        out, err = process.communicate(timeout=TIMEOUT_S)
    finally:
        process.kill()
    assert process.returncode == 0, err
    assert "page: error: a test line" in err.splitlines()


def test_export_html_opens_from_a_static_server(gl, tmp_path):
    site = tmp_path / "site"
    done = run_cli("view", "demo:vehicle", "--export-html", site)
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in site.iterdir()) == ["index.html", "input-0.glb",
                                                      "inputs.json", "viewer.js"]
    server = subprocess.Popen([sys.executable, "-u", "-m", "http.server", "0", "--bind",
                               "127.0.0.1", "-d", str(site)], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True)
    try:
        port = _first_line(server).split(" port ")[1].split()[0]
        with chromium() as browser:
            page = open_page(browser, f"http://127.0.0.1:{port}/?view=30,25&size=64x64")
            seen = state(page)
            covered = int((canvas_rgba(page)[..., 3] > 0).sum())
            # opened as a file (double-clicked): no browser lets it read its inputs, and it says so
            as_file = open_page(browser, (site / "index.html").as_uri())
            said = messages(as_file)
    finally:
        server.kill()
        server.wait()
    assert seen["ready"] and seen["errors"] == [], seen
    assert covered > 200
    assert said == ["error: this page was opened as a file: browsers let no page read the files "
                    "beside it. Serve its folder and open the address printed: python -m "
                    "http.server -d FOLDER"]


def test_bad_inputs_are_one_line():
    assert_one_line_error(run_cli("view", "no-such-file.obj", "--no-browser"), "no-such-file")
    assert_one_line_error(run_cli("view", "demo:cup", "--port", "70000"), "--port")
    assert_one_line_error(run_cli("view", "demo:cup", "--port", "8000", "--export-html", "x"),
                          "--port serves the page, --export-html writes it into a folder")
    assert_one_line_error(run_cli("view"), "INPUT")
    assert_one_line_error(run_cli("view", "demo:cup", "--parallax-steps", "2"),
                          "--parallax-steps applies to none of the inputs")
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert_one_line_error(run_cli("view", "demo:cup", "--no-browser", "--port", port),
                              f"cannot serve on 127.0.0.1:{port}")
