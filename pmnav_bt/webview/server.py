"""The web view's HTTP server: the standard library's ThreadingHTTPServer, a fixed set of
routes, nothing read from the disk by a name in a request.

Routes (GET):

- ``/``: the page (``static/view.html``, package data);
- ``/api/log``: the run so far as JSON (:meth:`Feed.snapshot`);
- ``/api/events?run=R&from=N``: Server-Sent Events, each new batch of ticks (``ticks``),
  a new run (``reset``), or the end (``ended``); a comment every ``KEEPALIVE_S``
  seconds finds a page that went away;
- ``/api/map``: the map's facts (``mapview.py``) or ``{"error": ...}``;
  ``/api/map.png``: the map picture;
- ``/api/frame/ID``: one camera frame (JPEG), by the number the log's tick carries.

Any other path is a 404: the server serves the one page and what the feed holds, and
never maps a request's path onto files. It listens on 127.0.0.1 unless told otherwise
(:func:`check_host`), and then answers only requests addressed to a loopback name (the
``Host`` header), so that a web site whose name was made to point at 127.0.0.1 (DNS
rebinding) cannot read the run from a visitor's browser. A page that goes away
mid-stream ends its own thread quietly.
"""

from __future__ import annotations

import ipaddress
import json
import socket
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from urllib.parse import parse_qs, urlsplit

from pmnav_bt.errors import PmNavError
from pmnav_bt.webview.feed import Feed

KEEPALIVE_S = 10.0
PAGE = "view.html"
LOOPBACK_NAMES = frozenset({"localhost", "127.0.0.1", "[::1]"})


def check_host(host: str, allow_remote: bool) -> str:
    """``host`` if it is a loopback address (or ``allow_remote``); else PmNavError: the
    view shows the run's camera and map to whoever can reach it."""
    if allow_remote:
        return host
    try:
        infos = socket.getaddrinfo(host, None)
    except (socket.gaierror, UnicodeError):
        raise PmNavError(f"--host {host!r}: not a known host name or address") from None
    if all(ipaddress.ip_address(info[4][0]).is_loopback for info in infos):
        return host
    raise PmNavError(
        f"--host {host!r} is not a loopback address: anyone on the network could see the "
        "run; add --allow-remote to serve it there anyway"
    )


def _page() -> bytes:
    return resources.files("pmnav_bt.webview").joinpath("static", PAGE).read_bytes()


class ViewServer(ThreadingHTTPServer):
    """Serves one Feed's page; ``close`` ends every open event stream, then the server."""

    daemon_threads = True
    allow_reuse_address = True

    def __init__(
        self, feed: Feed, host: str = "127.0.0.1", port: int = 0, allow_remote: bool = False
    ) -> None:
        self.feed = feed
        self.allow_remote = allow_remote
        self.closing = threading.Event()
        self._maps: dict[str, object] = {}
        self._map_lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self.address_family = socket.AF_INET6 if ":" in host else socket.AF_INET
        try:
            super().__init__((host, port), _Handler)
        except OSError as err:
            raise PmNavError(
                f"cannot serve on {host}:{port}: {err.strerror}; choose another port (0: any free)"
            ) from None

    def handle_error(self, request, client_address) -> None:
        """A page that went away (reset, broken pipe) is no error; anything else is."""
        import sys

        if not isinstance(sys.exc_info()[1], (ConnectionError, TimeoutError)):
            super().handle_error(request, client_address)

    @property
    def url(self) -> str:
        host, port = self.server_address[:2]
        host = f"[{host}]" if ":" in str(host) else host
        return f"http://{host}:{port}/"

    def start(self) -> ViewServer:
        """Serve in a daemon thread."""
        self._thread = threading.Thread(
            target=self.serve_forever, args=(0.1,), name="pmnav-view-http", daemon=True
        )
        self._thread.start()
        return self

    def close(self) -> None:
        self.closing.set()
        self.feed.end()  # wakes the streams
        self.shutdown()
        self.server_close()
        if self._thread is not None:
            self._thread.join()

    def map_view(self):
        """The map the feed's run names (cached): a MapView, or the error line."""
        building = self.feed.building or self.feed.header.get("run", {}).get("building")
        if not building:
            return (
                "this log names no building (it was written before tree log version 2): "
                "give pmnav view --building NAME"
            )
        with self._map_lock:
            if building not in self._maps:
                from pmnav_bt.webview.mapview import load_map_view

                try:
                    self._maps[building] = load_map_view(building)
                except PmNavError as err:
                    self._maps[building] = f"map not shown: {err}"
            return self._maps[building]


class _Handler(BaseHTTPRequestHandler):
    server: ViewServer
    protocol_version = "HTTP/1.1"

    def log_message(self, format: str, *args) -> None:  # noqa: A002 - the base's name
        """Quiet: a page's requests are no news."""

    def _addressed_to_loopback(self) -> bool:
        host = (self.headers.get("Host") or "localhost").strip().lower()
        name = host[: host.find("]") + 1] if host.startswith("[") else host.split(":")[0]
        return name in LOOPBACK_NAMES

    def do_GET(self) -> None:  # noqa: N802 - the base's name
        if not self.server.allow_remote and not self._addressed_to_loopback():
            self._send(HTTPStatus.FORBIDDEN, b"not a loopback host name", "text/plain")
            return
        url = urlsplit(self.path)
        route = url.path
        if route == "/":
            self._send(HTTPStatus.OK, _page(), "text/html; charset=utf-8")
        elif route == "/api/log":
            self._json(self.server.feed.snapshot())
        elif route == "/api/events":
            self._events(parse_qs(url.query))
        elif route == "/api/map":
            m = self.server.map_view()
            self._json({"error": m} if isinstance(m, str) else m.info)
        elif route == "/api/map.png":
            m = self.server.map_view()
            if isinstance(m, str):
                self._send(HTTPStatus.NOT_FOUND, m.encode(), "text/plain; charset=utf-8")
            else:
                self._send(HTTPStatus.OK, m.png, "image/png")
        elif route.startswith("/api/frame/") and route[11:].isdigit() and len(route) < 32:
            data = self.server.feed.frame(int(route[11:]))
            if data is None:
                self._send(HTTPStatus.NOT_FOUND, b"no such frame", "text/plain")
            else:
                self._send(HTTPStatus.OK, data, "image/jpeg")
        else:
            self._send(HTTPStatus.NOT_FOUND, b"not found", "text/plain")

    def _send(self, status: HTTPStatus, body: bytes, kind: str) -> None:
        self.send_response(status)
        self.send_header("Content-Type", kind)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        try:
            self.wfile.write(body)
        except (BrokenPipeError, ConnectionResetError):
            self.close_connection = True

    def _json(self, data: dict) -> None:
        self._send(HTTPStatus.OK, json.dumps(data).encode(), "application/json")

    def _events(self, query: dict[str, list[str]]) -> None:
        """Server-Sent Events: new ticks of the run the page holds, until it goes away."""
        feed = self.server.feed
        try:
            run = int(query.get("run", ["0"])[0])
            have = int(query.get("from", ["0"])[0])
            if have < 0:
                raise ValueError
        except ValueError:
            why = b"run and from must be integers, from at least 0"
            self._send(HTTPStatus.BAD_REQUEST, why, "text/plain")
            return
        self.close_connection = True
        self.send_response(HTTPStatus.OK)
        self.send_header("Content-Type", "text/event-stream")
        self.send_header("Cache-Control", "no-store")
        self.send_header("Connection", "close")
        self.end_headers()
        try:
            while not self.server.closing.is_set():
                news = feed.wait(run, have, KEEPALIVE_S)
                if news is None:
                    self.wfile.write(b": keep-alive\n\n")
                elif news.get("reset"):
                    self._event("reset", {})
                    return
                else:
                    have += len(news["ticks"])
                    self._event("ticks", news)
                    if news["ended"] or news["error"]:
                        return
                self.wfile.flush()
        except (BrokenPipeError, ConnectionResetError, TimeoutError):
            return  # the page went away

    def _event(self, name: str, data: dict) -> None:
        self.wfile.write(f"event: {name}\ndata: {json.dumps(data)}\n\n".encode())
        self.wfile.flush()
