"""Serving the viewer's site on 127.0.0.1 (only: nothing else can reach it) until Ctrl-C.

Files are served from memory; the page POSTs the errors it shows to ``/log``, and they are
printed as ``page: ...`` lines on the server's stderr, so a shader that does not compile in
the user's browser shows where the command runs too. ``input-K.glb?FLAG=VALUE...`` answers
that input's GLB made with those render options (`variants.Variants`); a value the CLI would
refuse is a 400 whose body is its one-line message.
"""

from __future__ import annotations

import sys
import threading
import webbrowser
from contextlib import contextmanager
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import urlsplit

from ..errors import ReliefkitError, UsageError

HOST = "127.0.0.1"
MAX_LOG_BYTES = 16 << 10  # one message the page posts
_TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
          ".json": "application/json", ".glb": "model/gltf-binary"}


def make_server(files: dict[str, bytes], port: int = 0, log=None,
                variants=None) -> ThreadingHTTPServer:
    """A server of ``files`` on 127.0.0.1:``port`` (0: a free one), not yet serving;
    ``variants`` (a `variants.Variants`) answers a GLB's URL with a query."""
    log = log or (lambda line: print(line, file=sys.stderr, flush=True))

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802 (http.server's name)
            url = urlsplit(self.path)
            name = url.path.lstrip("/") or "index.html"
            body = files.get(name)
            if url.query and variants is not None:  # a GLB with other render options
                try:
                    body = variants.answer(name, url.query) or body
                except ReliefkitError as exc:
                    self._text(400, f"error: {exc}")
                    return
            if body is None:
                self.send_error(404, f"no {name} here")
                return
            self.send_response(200)
            self.send_header("Content-Type", _TYPES.get(name[name.rfind("."):],
                                                        "application/octet-stream"))
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def _text(self, status: int, text: str):
            body = text.encode()
            self.send_response(status)
            self.send_header("Content-Type", "text/plain; charset=utf-8")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def do_POST(self):  # noqa: N802
            length = int(self.headers.get("Content-Length") or 0)
            if urlsplit(self.path).path != "/log" or not 0 <= length <= MAX_LOG_BYTES:
                self.send_error(400, "POST /log with a message of at most 16 KiB")
                return
            text = self.rfile.read(length).decode("utf-8", "replace")
            log("page: " + " ".join(text.split()))
            self.send_response(204)
            self.end_headers()

        def log_message(self, *args):  # requests are not news; errors come through /log
            pass

    try:
        return ThreadingHTTPServer((HOST, port), Handler)
    except OSError as exc:
        raise UsageError(f"cannot serve on {HOST}:{port}: {exc.strerror or exc}") from None


@contextmanager
def serving(files: dict[str, bytes], log=None, variants=None):
    """`make_server` of ``files`` on a free port, serving in a thread while the block runs;
    yields its base URL."""
    server = make_server(files, 0, log=log, variants=variants)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://{HOST}:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()


def serve(files: dict[str, bytes], port: int = 0, *, open_browser: bool = True,
          variants=None) -> None:
    """Serve ``files`` (and ``variants``) until Ctrl-C, printing the URL (and opening it
    unless told not to)."""
    server = make_server(files, port, variants=variants)
    url = f"http://{HOST}:{server.server_address[1]}/"
    print(f"serving {url} (Ctrl-C stops)", flush=True)
    if open_browser:
        webbrowser.open(url)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        print("stopped", flush=True)
    finally:
        server.server_close()
