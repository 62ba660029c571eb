"""When is the controller ready for a goal: odometry and the camera are fresh.

A goal that arrives before that (the usual case right after start-up: DDS discovery
and the first frames take a few seconds) waits for readiness, up to
``ready_timeout_s``, instead of failing at once with SENSOR_TIMEOUT. ``missing()``
names each input that is not there yet, with its topic, for the status and the
diagnostics.
"""

from __future__ import annotations

import time
from collections.abc import Callable


class Readiness:
    """Freshness of a Create3Base's odometry and camera.

    ``odom_fresh_s``/``camera_fresh_s``: the oldest message that still counts (s).
    """

    def __init__(self, base, odom_fresh_s: float, camera_fresh_s: float) -> None:
        self.base = base
        self.odom_fresh_s = float(odom_fresh_s)
        self.camera_fresh_s = float(camera_fresh_s)

    def _topic(self, name: str) -> str:
        try:
            return self.base.node.resolve_topic_name(name)
        except Exception:  # noqa: BLE001 - only for messages
            return name

    def missing(self) -> list[str]:
        """One line per input that is absent or stale; empty when ready."""
        s = self.base.sensors()
        opt = self.base.options
        out = []
        for what, age, limit, topic in (
            ("odometry", s["odom_age"], self.odom_fresh_s, opt.odom_topic),
            ("camera frame", s["camera_age"], self.camera_fresh_s, opt.image_topic),
        ):
            if age is None:
                out.append(f"no {what} received on {self._topic(topic)}")
            elif age > limit:
                out.append(f"last {what} on {self._topic(topic)} {age:.1f} s ago (> {limit:g} s)")
        return out

    def ready(self) -> bool:
        return not self.missing()

    def wait(
        self,
        timeout: float,
        cancelled: Callable[[], bool] = lambda: False,
        on_wait: Callable[[list[str], float], None] | None = None,
        poll: float = 0.1,
        report_every: float = 0.5,
    ) -> list[str]:
        """Block until ready, ``timeout`` s pass, or ``cancelled()``; return what is still
        missing (empty: ready). ``on_wait(missing, waited_s)`` is called every
        ``report_every`` s while waiting (feedback)."""
        t0 = time.monotonic()
        last_report = -float("inf")
        while True:
            missing = self.missing()
            waited = time.monotonic() - t0
            if not missing or waited >= timeout or cancelled():
                return missing
            if on_wait is not None and waited - last_report >= report_every:
                last_report = waited
                on_wait(missing, waited)
            time.sleep(poll)
