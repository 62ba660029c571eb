"""A small client for OpenAI-compatible chat completions (vLLM, Ollama, llama.cpp, OpenAI).

Images go inline as base64 PNG ``image_url`` parts. A 429 or 5xx answer, or a dropped
connection, is retried with exponential backoff (``Retry-After`` is respected); a request
that gets no answer within the timeout is not retried: a hanging server fails once, fast.
Every call appends a ``Usage`` record (tokens, latency, attempts) to ``client.usage`` and,
when configured, one JSON line to the usage log. The API key comes from the environment
and is sent only in the ``Authorization`` header: it is never logged or returned.
"""

from __future__ import annotations

import base64
import email.utils
import http.client
import json
import logging
import os
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import cv2
import numpy as np

from pmnav_bt.errors import ConfigError, VlmError

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.config import VlmConfig

log = logging.getLogger(__name__)

RETRY_STATUS = frozenset({408, 409, 429, 500, 502, 503, 504})
MAX_RETRY_AFTER_S = 120.0


@dataclass(frozen=True)
class Usage:
    """One chat call: tokens the server counted (None when it did not say), latency, tries."""

    purpose: str
    model: str
    prompt_tokens: int | None
    completion_tokens: int | None
    latency_s: float
    attempts: int
    ok: bool
    error: str = ""


@dataclass(frozen=True)
class ChatReply:
    """The text of the first choice and the call's usage."""

    text: str
    usage: Usage
    finish_reason: str | None = None


def png_data_url(image: np.ndarray) -> str:
    """A BGR (or grey) image as a ``data:image/png;base64,...`` URL."""
    ok, buf = cv2.imencode(".png", image)
    if not ok:
        raise VlmError("cannot encode the image as PNG")
    return "data:image/png;base64," + base64.b64encode(buf.tobytes()).decode("ascii")


def user_message(text: str, images: Sequence[np.ndarray] = ()) -> dict[str, Any]:
    """A user turn: the text, then each image as a base64 PNG part."""
    if not images:
        return {"role": "user", "content": text}
    parts: list[dict[str, Any]] = [{"type": "text", "text": text}]
    parts += [{"type": "image_url", "image_url": {"url": png_data_url(im)}} for im in images]
    return {"role": "user", "content": parts}


def fit_long_side(image: np.ndarray, long_side: int) -> np.ndarray:
    """Shrink an image so that its long side is at most ``long_side`` pixels."""
    h, w = image.shape[:2]
    s = long_side / max(h, w)
    if s >= 1.0:
        return image
    return cv2.resize(image, (max(1, round(w * s)), max(1, round(h * s))), cv2.INTER_AREA)


@dataclass
class VlmClient:
    """Chat completions against ``base_url`` (``.../v1``), one model."""

    base_url: str
    model: str
    api_key: str | None = field(default=None, repr=False)
    timeout_s: float = 60.0
    retries: int = 3
    backoff_s: float = 1.0
    max_tokens: int = 1024
    temperature: float = 0.0
    usage_log: Path | None = None
    sleep: Callable[[float], None] = time.sleep
    usage: list[Usage] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._lock = threading.Lock()

    @classmethod
    def from_config(cls, cfg: VlmConfig, env: Mapping[str, str] | None = None) -> VlmClient:
        """The client the ``vlm`` config section describes; the key from ``cfg.api_key_env``."""
        env = os.environ if env is None else env
        if not cfg.model:
            raise ConfigError(
                "vlm.model: no model named; set it to the model your server serves, "
                "e.g. --set vlm.model=Qwen/Qwen2.5-VL-7B-Instruct"
            )
        if not cfg.base_url.startswith(("http://", "https://")):
            raise ConfigError(f"vlm.base_url: {cfg.base_url!r} is not an http(s) URL")
        return cls(
            base_url=cfg.base_url,
            model=cfg.model,
            api_key=env.get(cfg.api_key_env) or None,
            timeout_s=cfg.timeout_s,
            retries=cfg.retries,
            backoff_s=cfg.backoff_s,
            max_tokens=cfg.max_tokens,
            temperature=cfg.temperature,
            usage_log=Path(cfg.usage_log) if cfg.usage_log else None,
        )

    @property
    def url(self) -> str:
        return self.base_url.rstrip("/") + "/chat/completions"

    def chat(
        self,
        messages: Sequence[Mapping[str, Any]],
        purpose: str = "chat",
        cancelled: threading.Event | None = None,
    ) -> ChatReply:
        """The server's answer to ``messages``; raises VlmError when there is none."""
        body = json.dumps(
            {
                "model": self.model,
                "messages": list(messages),
                "max_tokens": self.max_tokens,
                "temperature": self.temperature,
                "stream": False,
            }
        ).encode("utf-8")
        headers = {"Content-Type": "application/json", "Accept": "application/json"}
        if self.api_key:
            headers["Authorization"] = f"Bearer {self.api_key}"
        t0 = time.perf_counter()
        attempt = 0
        while True:
            attempt += 1
            try:
                data = self._post(body, headers)
            except _Retryable as err:
                if attempt > self.retries or (cancelled is not None and cancelled.is_set()):
                    self._record(purpose, t0, attempt, None, str(err))
                    raise VlmError(f"{self.url}: {err} (after {attempt} tries)") from None
                delay = err.retry_after
                if delay is None:
                    delay = self.backoff_s * 2 ** (attempt - 1)
                log.info("VLM %s: %s; retry %d in %.1f s", self.url, err, attempt, delay)
                if cancelled is not None and cancelled.wait(delay):
                    self._record(purpose, t0, attempt, None, "cancelled")
                    raise VlmError(f"{self.url}: cancelled") from None
                if cancelled is None:
                    self.sleep(delay)
                continue
            except VlmError as err:
                self._record(purpose, t0, attempt, None, str(err))
                raise
            text, finish = _reply_text(data, self.url)
            usage = self._record(purpose, t0, attempt, data.get("usage"), "")
            return ChatReply(text, usage, finish)

    def _post(self, body: bytes, headers: dict[str, str]) -> dict[str, Any]:
        req = urllib.request.Request(self.url, data=body, headers=headers, method="POST")
        try:
            with urllib.request.urlopen(req, timeout=self.timeout_s) as resp:
                raw = resp.read()
        except urllib.error.HTTPError as err:
            detail = _excerpt(err.read())
            if err.code in RETRY_STATUS:
                raise _Retryable(
                    f"HTTP {err.code} {detail}", _retry_after(err.headers.get("Retry-After"))
                ) from None
            hint = " (check the API key variable)" if err.code in (401, 403) else ""
            hint = hint or (" (check vlm.base_url ends in /v1)" if err.code == 404 else "")
            raise VlmError(f"{self.url}: HTTP {err.code} {detail}{hint}") from None
        except TimeoutError:
            raise VlmError(f"{self.url}: no answer within {self.timeout_s:g} s") from None
        except urllib.error.URLError as err:
            if isinstance(err.reason, TimeoutError):
                raise VlmError(f"{self.url}: no answer within {self.timeout_s:g} s") from None
            raise _Retryable(f"cannot connect: {err.reason}", None) from None
        except (ConnectionError, http.client.HTTPException) as err:
            raise _Retryable(f"connection dropped: {type(err).__name__}", None) from None
        try:
            data = json.loads(raw)
        except ValueError:
            raise VlmError(f"{self.url}: the answer is not JSON: {_excerpt(raw)}") from None
        if not isinstance(data, dict):
            raise VlmError(f"{self.url}: the answer is not a JSON object: {_excerpt(raw)}")
        return data

    def _record(self, purpose, t0, attempts, usage, error) -> Usage:
        usage = usage if isinstance(usage, dict) else {}
        u = Usage(
            purpose=purpose,
            model=self.model,
            prompt_tokens=usage.get("prompt_tokens"),
            completion_tokens=usage.get("completion_tokens"),
            latency_s=round(time.perf_counter() - t0, 4),
            attempts=attempts,
            ok=not error,
            error=error,
        )
        log.info(
            "VLM %s %s: %s prompt + %s completion tokens, %.2f s, %d tries%s",
            self.model, purpose, u.prompt_tokens, u.completion_tokens, u.latency_s, attempts,
            f", failed: {error}" if error else "",
        )  # fmt: skip
        with self._lock:
            self.usage.append(u)
            if self.usage_log is not None:
                with open(self.usage_log, "a", encoding="utf-8") as f:
                    f.write(json.dumps(asdict(u)) + "\n")
        return u

    def totals(self) -> dict[str, float]:
        """Calls, failed calls, tokens and seconds so far."""
        with self._lock:
            us = list(self.usage)
        return {
            "calls": len(us),
            "failed_calls": sum(not u.ok for u in us),
            "prompt_tokens": sum(u.prompt_tokens or 0 for u in us),
            "completion_tokens": sum(u.completion_tokens or 0 for u in us),
            "latency_s": round(sum(u.latency_s for u in us), 3),
        }


class _Retryable(Exception):
    def __init__(self, message: str, retry_after: float | None):
        super().__init__(message)
        self.retry_after = retry_after


def _retry_after(value: str | None) -> float | None:
    """Seconds from a Retry-After header (delta seconds or an HTTP date), capped."""
    if not value:
        return None
    try:
        s = float(value)
    except ValueError:
        try:
            when = email.utils.parsedate_to_datetime(value)
        except (TypeError, ValueError):
            return None
        s = when.timestamp() - time.time()
    return min(max(s, 0.0), MAX_RETRY_AFTER_S)


def _excerpt(raw: bytes | str, n: int = 200) -> str:
    text = raw.decode("utf-8", "replace") if isinstance(raw, bytes) else raw
    text = " ".join(text.split())
    return text[:n] + ("..." if len(text) > n else "")


def _reply_text(data: dict[str, Any], url: str) -> tuple[str, str | None]:
    try:
        choice = data["choices"][0]
        content = choice["message"]["content"]
    except (KeyError, IndexError, TypeError):
        excerpt = _excerpt(json.dumps(data))
        raise VlmError(f"{url}: no choices[0].message.content in {excerpt}") from None
    if isinstance(content, list):  # some servers answer in parts
        content = "".join(p.get("text", "") for p in content if isinstance(p, dict))
    if content is None:
        content = ""
    return str(content), choice.get("finish_reason")
