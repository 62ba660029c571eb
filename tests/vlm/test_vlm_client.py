"""The chat client against a real local HTTP server (127.0.0.1, a free port)."""

from __future__ import annotations

import base64
import json

import cv2
import numpy as np
import pytest

from pmnav_bt.config import load_config
from pmnav_bt.errors import ConfigError, VlmError
from pmnav_bt.vlm.client import VlmClient, user_message
from pmnav_bt.vlm.scripted_server import ChatServer, Reply, Script


def client(server: ChatServer, **kw) -> tuple[VlmClient, list[float]]:
    slept: list[float] = []
    kw.setdefault("timeout_s", 5.0)
    c = VlmClient(server.base_url, "test-model", sleep=slept.append, **kw)
    return c, slept


def test_an_answer_and_its_usage():
    with ChatServer(Script([Reply("hello")])) as s:
        c, _ = client(s)
        reply = c.chat([user_message("hi")], purpose="test")
    assert reply.text == "hello"
    assert reply.finish_reason == "stop"
    assert reply.usage.ok and reply.usage.attempts == 1 and reply.usage.purpose == "test"
    assert reply.usage.completion_tokens == 1
    req = s.requests[0]
    assert req["model"] == "test-model" and req["messages"][0]["content"] == "hi"
    assert c.totals()["calls"] == 1


def test_images_go_inline_as_base64_png():
    img = np.zeros((20, 30, 3), np.uint8)
    img[5:10, 5:10] = (0, 0, 255)
    with ChatServer(Script([Reply("ok")])) as s:
        client(s)[0].chat([user_message("look", [img])])
    parts = s.requests[0]["messages"][0]["content"]
    assert parts[0] == {"type": "text", "text": "look"}
    url = parts[1]["image_url"]["url"]
    assert url.startswith("data:image/png;base64,")
    back = cv2.imdecode(np.frombuffer(base64.b64decode(url.split(",", 1)[1]), np.uint8), 1)
    assert np.array_equal(back, img)


def test_429_then_success_waits_as_retry_after_says():
    replies = [Reply("slow down", status=429, headers={"Retry-After": "7"}), Reply("done")]
    with ChatServer(Script(replies)) as s:
        c, slept = client(s, backoff_s=0.5)
        reply = c.chat([user_message("x")])
    assert reply.text == "done" and reply.usage.attempts == 2
    assert slept == [7.0]  # Retry-After, not the backoff
    assert len(s.requests) == 2


def test_500s_back_off_exponentially_then_succeed():
    replies = [Reply(status=500), Reply(status=503), Reply("finally")]
    with ChatServer(Script(replies)) as s:
        c, slept = client(s, backoff_s=0.5, retries=3)
        assert c.chat([user_message("x")]).text == "finally"
    assert slept == [0.5, 1.0]


def test_500s_beyond_the_retries_are_a_vlm_error():
    with ChatServer(Script([Reply("boom", status=500)])) as s:
        c, slept = client(s, backoff_s=0.1, retries=2)
        with pytest.raises(VlmError, match=r"HTTP 500.*after 3 tries"):
            c.chat([user_message("x")])
    assert len(s.requests) == 3 and len(slept) == 2
    assert not c.usage[-1].ok and c.usage[-1].attempts == 3


def test_a_reply_after_the_timeout_fails_once_without_retrying():
    with ChatServer(Script([Reply("too late", delay_s=3.0)])) as s:
        c, slept = client(s, timeout_s=0.3, retries=3)
        with pytest.raises(VlmError, match="no answer within 0.3 s"):
            c.chat([user_message("x")])
    assert len(s.requests) == 1 and slept == []


def test_client_errors_are_not_retried_and_say_what_to_check():
    with ChatServer(Script([Reply("bad key", status=401)])) as s:
        c, _ = client(s)
        with pytest.raises(VlmError, match="HTTP 401.*API key"):
            c.chat([user_message("x")])
    assert len(s.requests) == 1


def test_a_body_that_is_not_json_is_a_vlm_error():
    with (
        ChatServer(Script([Reply(body="<html>proxy error</html>")])) as s,
        pytest.raises(VlmError, match="not JSON"),
    ):
        client(s)[0].chat([user_message("x")])


def test_no_server_is_a_vlm_error_after_the_retries():
    with ChatServer(Script([Reply("x")])) as s:
        url = s.base_url
    c = VlmClient(url, "m", timeout_s=1.0, retries=1, sleep=lambda _: None)
    with pytest.raises(VlmError, match="cannot connect"):
        c.chat([user_message("x")])


def test_the_key_comes_from_the_environment_and_is_never_logged(tmp_path):
    cfg = load_config(
        None,
        ["vlm.model=m", "vlm.api_key_env=MY_KEY", f"vlm.usage_log={tmp_path / 'usage.jsonl'}"],
    )
    with ChatServer(Script([Reply("ok"), Reply("no", status=500)])) as s:
        cfg = cfg.model_copy(update={"vlm": cfg.vlm.model_copy(update={"base_url": s.base_url})})
        c = VlmClient.from_config(cfg.vlm, env={"MY_KEY": "sk-secret-123"})
        c.retries = 0
        c.chat([user_message("x")])
        with pytest.raises(VlmError) as err:
            c.chat([user_message("x")])
    assert s.authorization[0] == "Bearer sk-secret-123"
    log = (tmp_path / "usage.jsonl").read_text()
    assert len(log.splitlines()) == 2 and json.loads(log.splitlines()[1])["ok"] is False
    for text in (log, str(err.value), repr(c), json.dumps(s.requests)):
        assert "sk-secret-123" not in text


def test_no_key_sends_no_authorization():
    with ChatServer(Script([Reply("ok")])) as s:
        client(s)[0].chat([user_message("x")])
    assert s.authorization == [None]


def test_a_config_without_a_model_is_a_config_error():
    with pytest.raises(ConfigError, match="vlm.model"):
        VlmClient.from_config(load_config().vlm)
