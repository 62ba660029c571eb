"""``pmnav view LOG``: serve the web view of a tree log (replay), or of one a run is
writing (``--follow``); mounted on ``pmnav`` by ``pmnav_bt/cli.py``. Only typer is
imported at module level."""

from __future__ import annotations

import time
from pathlib import Path

import typer

from pmnav_bt.errors import PmNavError

DEFAULT_PORT = 8765

HOST_OPT = typer.Option(
    "127.0.0.1", "--host", help="Address to serve on; only loopback unless --allow-remote."
)
ALLOW_REMOTE_OPT = typer.Option(
    False, "--allow-remote", help="Serve on a --host other machines can reach (the run's camera)."
)


def start_server(feed, host: str, port: int, allow_remote: bool):
    """A ViewServer for ``feed`` on ``host``:``port``, serving in a thread."""
    from pmnav_bt.webview.server import ViewServer, check_host

    if not 0 <= port <= 65535:
        raise PmNavError(f"--port {port}: choose 0 (any free port) to 65535")
    return ViewServer(feed, check_host(host, allow_remote), port, allow_remote).start()


def view(
    log: Path = typer.Argument(..., help="A tree log (JSON lines), e.g. out/run/*.tree.jsonl."),
    follow: bool = typer.Option(
        False, "--follow", help="Follow the log as a run writes it (it may not exist yet)."
    ),
    port: int = typer.Option(DEFAULT_PORT, "--port", help="Port to serve on (0: any free one)."),
    host: str = HOST_OPT,
    allow_remote: bool = ALLOW_REMOTE_OPT,
    building: str | None = typer.Option(
        None, "--building", help="The building to draw (default: the one the log names)."
    ),
) -> None:
    """Show a run in a browser: the tree, what it knew, the map and the camera, with a
    time slider (replay), or live as the run writes its log (--follow)."""
    from pmnav_bt.webview.feed import Feed, LogFollower

    feed = Feed(str(log), live=follow, building=building)
    follower = None
    if follow:
        follower = LogFollower(log, feed).start()
    else:
        feed.load(log)
        if feed.warning:
            typer.echo(f"pmnav: warning: {feed.warning}", err=True)
    server = start_server(feed, host, port, allow_remote)
    typer.echo(f"pmnav view: {server.url} ({len(feed.ticks)} ticks so far; Ctrl-C stops)")
    told = ""
    try:
        while True:
            time.sleep(0.5)
            if feed.error and feed.error != told:
                told = feed.error
                typer.echo(f"pmnav: {feed.error}", err=True)
    except KeyboardInterrupt:
        pass
    finally:
        if follower is not None:
            follower.stop()
        server.close()
