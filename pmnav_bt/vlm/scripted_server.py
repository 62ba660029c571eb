"""A local OpenAI-compatible chat server with scripted answers, for tests, benchmarks and
running the ``vlm`` back ends end to end without a model.

``ChatServer`` serves ``POST /v1/chat/completions`` (and ``GET /v1/models``) on
127.0.0.1 from a thread; a *responder* decides each answer. Two responders:

- ``Script``: a queue of ``Reply`` objects (text, HTTP status, headers, delay), for tests;
- ``PlanningResponder``: reads the planning prompt (building, start, goal), computes the
  correct plan with the graph planner and answers it, every node of the route with its
  action; with probability ``wrong`` it corrupts the answer instead (a wrong landmark, an
  unconnected step, a wrong turn, a wrong goal, prose with no plan, truncated JSON).
  Re-prompts are answered the same way, with a fresh draw. Coarse-direction questions are
  answered ``{"angle": null}`` (it cannot see).

    python -m pmnav_bt.vlm.scripted_server --port 8011 --wrong 0.3 --seed 0

Its answers prove the plumbing, not a model.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import threading
import time
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

import numpy as np

CORRUPTIONS = (
    "wrong_landmark",
    "unconnected",
    "wrong_turn",
    "wrong_goal",
    "prose",
    "truncated",
)


@dataclass
class Reply:
    """One scripted answer: the assistant text (or a raw body), the status, headers, delay."""

    text: str = ""
    status: int = 200
    headers: dict[str, str] = field(default_factory=dict)
    delay_s: float = 0.0
    body: str | None = None  # sent as is instead of a chat completion
    finish_reason: str = "stop"


Responder = Callable[[dict[str, Any]], Reply]


class Script:
    """Answers from a queue; once empty, the last reply is repeated."""

    def __init__(self, replies: list[Reply]):
        self.replies = list(replies)
        self._lock = threading.Lock()

    def __call__(self, request: dict[str, Any]) -> Reply:
        with self._lock:
            return self.replies.pop(0) if len(self.replies) > 1 else self.replies[0]


class ChatServer:
    """An OpenAI-compatible server on 127.0.0.1 (port 0: a free one), in a daemon thread."""

    def __init__(self, responder: Responder, port: int = 0, model: str = "scripted"):
        self.responder = responder
        self.model = model
        self.requests: list[dict[str, Any]] = []
        self.authorization: list[str | None] = []
        self._stop = threading.Event()
        server = self

        class Handler(BaseHTTPRequestHandler):
            protocol_version = "HTTP/1.1"

            def log_message(self, *args) -> None:  # quiet
                pass

            def do_GET(self) -> None:  # noqa: N802 - http.server's name
                if self.path.rstrip("/").endswith("/models"):
                    self._send(200, {"object": "list", "data": [{"id": server.model}]})
                else:
                    self._send(404, {"error": {"message": f"no route {self.path}"}})

            def do_POST(self) -> None:  # noqa: N802
                if not self.path.rstrip("/").endswith("/chat/completions"):
                    self._send(404, {"error": {"message": f"no route {self.path}"}})
                    return
                n = int(self.headers.get("Content-Length") or 0)
                try:
                    req = json.loads(self.rfile.read(n))
                except ValueError:
                    self._send(400, {"error": {"message": "body is not JSON"}})
                    return
                server.requests.append(req)
                server.authorization.append(self.headers.get("Authorization"))
                reply = server.responder(req)
                if reply.delay_s and server._stop.wait(reply.delay_s):
                    return
                if reply.body is not None:
                    self._send_raw(reply.status, reply.body.encode(), reply.headers)
                elif reply.status != 200:
                    err = {"error": {"message": reply.text or f"status {reply.status}"}}
                    self._send(reply.status, err, reply.headers)
                else:
                    self._send(200, completion(reply, req.get("model", server.model)))

            def _send(self, status: int, data: dict, headers: dict | None = None) -> None:
                self._send_raw(status, json.dumps(data).encode(), headers or {})

            def _send_raw(self, status: int, body: bytes, headers: dict) -> None:
                try:
                    self.send_response(status)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(body)))
                    for k, v in headers.items():
                        self.send_header(k, v)
                    self.end_headers()
                    self.wfile.write(body)
                except (BrokenPipeError, ConnectionResetError):
                    pass  # the client gave up (timed out)

        self._httpd = ThreadingHTTPServer(("127.0.0.1", port), Handler)
        self._httpd.daemon_threads = True
        self._thread = threading.Thread(target=self._httpd.serve_forever, daemon=True)

    @property
    def port(self) -> int:
        return self._httpd.server_address[1]

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self.port}/v1"

    def start(self) -> ChatServer:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()  # ends delayed replies
        self._httpd.shutdown()
        self._httpd.server_close()

    def __enter__(self) -> ChatServer:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()


def completion(reply: Reply, model: str) -> dict[str, Any]:
    """A chat.completion object carrying ``reply.text``, with rough token counts."""
    return {
        "id": f"chatcmpl-{zlib.crc32(reply.text.encode()):08x}",
        "object": "chat.completion",
        "created": int(time.time()),
        "model": model,
        "choices": [
            {
                "index": 0,
                "message": {"role": "assistant", "content": reply.text},
                "finish_reason": reply.finish_reason,
            }
        ],
        "usage": {
            "prompt_tokens": 0,
            "completion_tokens": max(1, len(reply.text) // 4),
            "total_tokens": max(1, len(reply.text) // 4),
        },
    }


# -- the planning responder ----------------------------------------------------------------

_BUILDING = re.compile(r'(?:building \(an? [^,]+, |building, )"([^"]+)"')
_GOAL = re.compile(r'position to (\S+) \("')
_START = re.compile(
    r"[Pp]osition: on \S+ at \((-?[\d.]+), (-?[\d.]+)\)(?:, facing \w+ \(heading (\d+) deg)?"
)


def request_text(request: dict[str, Any]) -> tuple[str, str, int]:
    """(first user text, last user text, assistant turns so far) of a chat request."""
    texts, answers = [], 0
    for m in request.get("messages", []):
        if m.get("role") == "assistant":
            answers += 1
            continue
        c = m.get("content")
        if isinstance(c, list):
            c = "".join(p.get("text", "") for p in c if isinstance(p, dict))
        texts.append(str(c or ""))
    return (texts[0] if texts else ""), (texts[-1] if texts else ""), answers


class PlanningResponder:
    """Correct plans from the graph planner, ``wrong`` of them corrupted (seeded)."""

    def __init__(self, wrong: float = 0.3, seed: int = 0, building_dir: str | None = None):
        self.wrong = wrong
        self.seed = seed
        self.building_dir = building_dir
        self._maps: dict[str, Any] = {}
        self._lock = threading.Lock()
        self.counts: dict[str, int] = {"correct": 0, **{c: 0 for c in CORRUPTIONS}}

    def __call__(self, request: dict[str, Any]) -> Reply:
        first, _last, answers = request_text(request)
        if "panorama" in first:
            return Reply('{"angle": null}')
        try:
            pm, sp, goal = self._task(first)
        except (ValueError, KeyError) as err:
            return Reply(f"I cannot read the task ({err}).")
        rng = np.random.default_rng([self.seed, zlib.crc32(first.encode()), answers])
        steps = self.correct_steps(pm, sp, goal)
        kind = "correct"
        if rng.random() < self.wrong:
            kind = CORRUPTIONS[int(rng.integers(len(CORRUPTIONS)))]
        with self._lock:
            self.counts[kind] += 1
        return Reply(self.answer(pm, steps, goal, kind, rng))

    def _map(self, name: str):
        from pmnav_bt.map.catalogue import load_building
        from pmnav_bt.map.priori_map import parse_building

        with self._lock:
            if name not in self._maps:
                src = f"{self.building_dir}/{name}.yaml" if self.building_dir else name
                self._maps[name] = parse_building(load_building(src))
            return self._maps[name]

    def _task(self, text: str):
        from pmnav_bt.planning.resolve import StartPoint

        b, g, s = _BUILDING.search(text), _GOAL.search(text), _START.search(text)
        if not (b and g and s):
            raise ValueError("no building, goal or start in the prompt")
        pm = self._map(b.group(1))
        loc = pm.locate(float(s.group(1)), float(s.group(2)))
        yaw = math.radians(float(s.group(3))) if s.group(3) is not None else None
        return pm, StartPoint("prompt", loc.segment, loc.t, yaw), g.group(1)

    @staticmethod
    def correct_steps(pm, sp, goal: str) -> list[tuple[str, str]]:
        """Every node of the shortest route with the action there (the goal: arrive)."""
        from pmnav_bt.geometry import heading, relative_action
        from pmnav_bt.planning.graph_planner import shortest_route

        nodes, _, start_xy = shortest_route(pm, sp, pm.places[goal].node)
        pts = [np.asarray(start_xy)] + [pm.node_xy(n) for n in nodes]
        steps = []
        for i, n in enumerate(nodes):
            j = i + 1
            if j == len(pts) - 1:
                steps.append((goal, "arrive"))
                break
            prev = next(
                (pts[k] for k in range(j - 1, -1, -1) if np.linalg.norm(pts[j] - pts[k]) > 1e-6),
                None,
            )
            h_in = heading(prev, pts[j]) if prev is not None else (sp.heading or 0.0)
            steps.append((n, relative_action(h_in, heading(pts[j], pts[j + 1])).value))
        return steps

    @staticmethod
    def answer(pm, steps: list[tuple[str, str]], goal: str, kind: str, rng) -> str:
        """The answer text of ``kind``: the correct steps, or one corruption of them. The
        first step is never the corrupted one (its action cannot be checked when the robot
        stands on it with an unknown heading)."""
        steps = list(steps)
        mid = list(range(1, len(steps) - 1))
        if not mid and kind in ("wrong_landmark", "unconnected", "wrong_turn"):
            kind = "wrong_goal"
        if kind == "prose":
            return "Walk along the corridor and ask someone at the reception for the way."
        if kind == "wrong_landmark":
            i = int(rng.choice(mid))
            steps[i] = (f"room{900 + int(rng.integers(99))}", steps[i][1])
        elif kind == "unconnected":
            on_route = {pm.places[n].node if n in pm.places else n for n, _ in steps}
            corridors = {s.corridor for n in on_route for s in pm.segments_at(n)}
            far = [
                n
                for n in pm.nodes
                if not pm.nodes[n].is_key
                and n not in on_route
                and not {s.corridor for s in pm.segments_at(n)} & corridors
            ]
            far = far or [n for n in pm.nodes if n not in on_route and not pm.nodes[n].is_key]
            i = int(rng.choice(mid))
            steps.insert(i, (str(rng.choice(far)), "go straight"))
        elif kind == "wrong_turn":
            flip = {
                "turn left": "turn right",
                "turn right": "turn left",
                "go straight": "turn left",
                "turn around": "go straight",
            }
            turns = [k for k in mid if steps[k][1] in ("turn left", "turn right")]
            i = int(rng.choice(turns or mid))
            steps[i] = (steps[i][0], flip[steps[i][1]])
        elif kind == "wrong_goal":
            others = [
                r.id for r in pm.building.rooms if pm.places[r.id].node != pm.places[goal].node
            ]
            steps[-1] = (str(rng.choice(others)), "arrive")
        body = json.dumps({"plan": [{"landmark": n, "action": a} for n, a in steps]})
        if kind == "truncated":
            return "```json\n" + body[: max(10, int(len(body) * 0.6))]
        reasoning = (
            "Step 1: the robot is on its segment; the goal lies along the corridors ahead.\n"
            "Step 2: the key waypoints are on the route below.\n"
        )
        return f"{reasoning}Step 3:\n```json\n{body}\n```"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--port", type=int, default=8011)
    ap.add_argument("--wrong", type=float, default=0.3, help="share of corrupted answers")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--building-dir", default=None, help="folder of <name>.yaml building files")
    ap.add_argument("--hang", action="store_true", help="never answer (benchmarks)")
    args = ap.parse_args(argv)
    if args.hang:
        responder: Responder = lambda req: Reply("", delay_s=3600.0)  # noqa: E731
    else:
        responder = PlanningResponder(args.wrong, args.seed, args.building_dir)
    server = ChatServer(responder, args.port)
    print(f"scripted VLM server on {server.base_url} (wrong {args.wrong:.0%})", flush=True)
    try:
        server._httpd.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server._httpd.server_close()


if __name__ == "__main__":  # pragma: no cover
    main()
