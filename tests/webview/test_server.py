"""``pmnav view``'s server: a log written before version 2 replays; bad logs (cut, huge,
not a log) are one line on the command line and in the page; a page that goes away
mid-stream ends quietly; no request reaches a file; non-loopback hosts are refused."""

from __future__ import annotations

import http.client
import json
import socket
import time
from pathlib import Path

import pytest

from pmnav_bt.errors import PmNavError
from pmnav_bt.experiments.cli import main
from pmnav_bt.treelog import read_tree_log
from pmnav_bt.webview.feed import Feed, FeedWriter, LogFollower
from pmnav_bt.webview.server import ViewServer, check_host

DATA = Path(__file__).parent / "data"
V1_LOG = DATA / "v1_fig2_room17.tree.jsonl"  # written by pmnav before tree log version 2


def get(server: ViewServer, path: str) -> tuple[int, bytes]:
    conn = http.client.HTTPConnection(*server.server_address[:2], timeout=10)
    conn.request("GET", path)
    r = conn.getresponse()
    body = r.read()
    conn.close()
    return r.status, body


@pytest.fixture()
def serve():
    servers = []

    def start(feed: Feed) -> ViewServer:
        servers.append(ViewServer(feed).start())
        return servers[-1]

    yield start
    for s in servers:
        s.close()


def test_a_version_1_log_replays_with_its_statuses(serve):
    log = read_tree_log(V1_LOG)
    server = serve(Feed(str(V1_LOG), live=False).load(V1_LOG))
    status, body = get(server, "/api/log")
    page = json.loads(body)
    assert status == 200 and page["header"]["version"] == 1 and page["ended"]
    assert len(page["ticks"]) == len(log.ticks)
    ids = [n["id"] for n in page["nodes"]]
    for sent, rec in zip(page["ticks"], log.ticks, strict=True):
        assert sent["i"] == rec["tick"] and "v" not in sent
        assert {ids[int(k)]: v for k, v in sent["s"].items()} == {
            k: v[0] for k, v in rec["status"].items()
        }
    # no building named in a version 1 log: the map says so in one line
    assert "--building" in json.loads(get(server, "/api/map")[1])["error"]


def _cli_error(args, capsys) -> str:
    with pytest.raises(SystemExit) as exit_:
        main(["view", *map(str, args)])
    err = capsys.readouterr().err.strip()
    assert exit_.value.code == 2 and len(err.splitlines()) == 1, err
    return err


def test_bad_logs_are_one_line_on_the_command_line(tmp_path, capsys):
    text = tmp_path / "notes.jsonl"
    text.write_text("hello\n", encoding="utf-8")
    assert "notes.jsonl: line 1" in _cli_error([text], capsys)
    huge = tmp_path / "huge.jsonl"
    with open(huge, "wb") as f:
        f.truncate(300 << 20)  # sparse: the size alone is refused, nothing is read
    assert "limit is 256" in _cli_error([huge], capsys)
    assert "not a loopback" in _cli_error([V1_LOG, "--host", "8.8.8.8"], capsys)


def test_a_cut_log_replays_what_is_whole_with_a_warning(tmp_path, serve):
    cut = tmp_path / "cut.jsonl"
    data = V1_LOG.read_bytes()
    cut.write_bytes(data[: len(data) - 300])  # the last record loses its end
    feed = Feed(str(cut), live=False).load(cut)
    page = json.loads(get(serve(feed), "/api/log")[1])
    assert "cut short" in page["warning"] and not page["error"]
    assert len(page["ticks"]) == len(read_tree_log(V1_LOG).ticks) - 1


def test_a_followed_log_that_turns_bad_stops_with_one_line(tmp_path, serve):
    path = tmp_path / "run.tree.jsonl"
    feed = Feed(str(path), live=True)
    follower = LogFollower(path, feed).start()
    try:
        server = serve(feed)
        lines = V1_LOG.read_text(encoding="utf-8").splitlines(keepends=True)
        path.write_text("".join(lines[:4]) + lines[4][:50], encoding="utf-8")  # mid-write
        _wait(lambda: len(feed.ticks) == 3)
        with open(path, "a", encoding="utf-8") as f:
            f.write(lines[4][50:] + "not json\n")
        _wait(lambda: feed.error)
        page = json.loads(get(server, "/api/log")[1])
    finally:
        follower.stop()
    assert len(page["ticks"]) == 4  # the line written in two goes was read whole
    assert page["error"].startswith(f"{path}: line 6") and "\n" not in page["error"]


def _wait(cond, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.02)


def _events(sock: socket.socket, want: int) -> list[dict]:
    """Read Server-Sent Events from ``sock`` until ``want`` ticks came."""
    buf, got = b"", []
    while sum(len(e.get("ticks", [])) for e in got) < want:
        chunk = sock.recv(65536)
        assert chunk, "the stream ended early"
        buf += chunk
        while b"\n\n" in buf:
            block, buf = buf.split(b"\n\n", 1)
            data = [ln[6:] for ln in block.split(b"\n") if ln.startswith(b"data: ")]
            if data:
                got.append(json.loads(data[0]))
    return got


def test_live_ticks_stream_and_a_page_that_goes_away_ends_quietly(serve, capfd):
    feed = Feed("live", live=True)
    writer = FeedWriter(feed)
    server = serve(feed)
    lines = V1_LOG.read_text(encoding="utf-8").splitlines(keepends=True)
    writer.write(lines[0])
    _wait(lambda: feed.run == 1)
    sock = socket.create_connection(server.server_address[:2], timeout=10)
    sock.sendall(b"GET /api/events?run=1&from=0 HTTP/1.1\r\nHost: localhost\r\n\r\n")
    writer.write("".join(lines[1:4]))
    assert [t["i"] for e in _events(sock, 3) for t in e["ticks"]] == [0, 1, 2]
    sock.close()  # the page goes away mid-stream
    writer.write("".join(lines[4:]))
    writer.close()
    _wait(lambda: feed.ended)
    page = json.loads(get(server, "/api/log")[1])
    assert len(page["ticks"]) == len(lines) - 1 and page["ended"]
    status, body = get(server, "/api/events?run=1&from=29")  # ends: the run is over
    assert status == 200 and b"event: ticks" in body and b'"ended": true' in body
    assert "Traceback" not in capfd.readouterr().err


@pytest.mark.parametrize(
    "path",
    [
        "/../pyproject.toml",
        "/%2e%2e/%2e%2e/etc/passwd",
        "//etc/passwd",
        "/static/view.html",
        "/api/frame/../../../etc/passwd",
        "/api/frame/0",
        f"/{V1_LOG}",
    ],
)
def test_no_request_reaches_a_file(serve, path):
    server = serve(Feed(str(V1_LOG), live=False).load(V1_LOG))
    status, body = get(server, path)
    assert status == 404 and b"root:" not in body and b"tree" not in body


def test_the_page_is_served_and_hosts_beyond_loopback_are_refused(serve):
    server = serve(Feed("x", live=False))
    status, body = get(server, "/")
    assert status == 200 and b"<title>pmnav view</title>" in body
    conn = http.client.HTTPConnection(*server.server_address[:2], timeout=10)
    conn.request("GET", "/", headers={"Host": "rebound.example:8765"})  # DNS rebinding
    assert conn.getresponse().status == 403
    conn.close()
    assert check_host("localhost", False) == "localhost"
    assert check_host("0.0.0.0", True) == "0.0.0.0"
    with pytest.raises(PmNavError, match="--allow-remote"):
        check_host("0.0.0.0", False)


def test_a_busy_port_is_one_line(serve):
    server = serve(Feed("x", live=False))
    with pytest.raises(PmNavError, match="cannot serve on"):
        ViewServer(Feed("y", live=False), port=server.server_address[1])


def test_the_view_entry_is_checked_and_newer_versions_refused(tmp_path):
    nodes = [{"id": "a", "name": "A", "class": "Sequence", "parent": None}]
    tick = {"type": "tick", "tick": 0, "time": 0.0, "status": {"a": "RUNNING"},
            "feedback": {}, "blackboard": {}}  # fmt: skip
    path = tmp_path / "t.jsonl"

    def write(header: dict, view: dict) -> None:
        recs = [{"type": "tree", "nodes": nodes, **header}, {**tick, "view": view}]
        path.write_text("".join(json.dumps(r) + "\n" for r in recs), encoding="utf-8")

    write({"version": 2}, {"pose": [1.0, 2.0, 0.5], "plan": None, "later": "ignored"})
    assert read_tree_log(path).ticks[0]["view"]["pose"] == [1.0, 2.0, 0.5]
    write({"version": 2}, {"pose": [1.0, "x", 0.5]})
    with pytest.raises(PmNavError, match=r"line 2: tick record: view.pose: expected \[x, y, yaw\]"):
        read_tree_log(path)
    write({"version": 3}, {})
    with pytest.raises(PmNavError, match="schema version 3 is newer"):
        read_tree_log(path)


def test_the_recorded_v2_log_draws_its_map_on_any_machine(serve):
    """The browser test's log names a built-in, so its map loads on a clean clone (a path
    into one machine's checkout made the page wait for a map that never came)."""
    log = DATA / "v2_fig2_room17_failed.tree.jsonl"
    server = serve(Feed(str(log), live=False).load(log))
    status, body = get(server, "/api/map")
    assert status == 200 and json.loads(body).get("building") == "fig2_hospital", body[:200]
