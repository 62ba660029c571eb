"""``--record FILE.mcap``: the run's topics in MCAP with ROS 2 encodings (like ``ros2 bag``).

Each topic is subscribed *raw* (the serialized CDR bytes, no decoding) and written as
an MCAP message on a channel with ``message_encoding: cdr`` and a ``ros2msg`` schema
(the .msg definition with its dependencies, the format rosbag2's MCAP storage
writes). Foxglove, ``ros2 bag info/play`` and ``mcap_ros2.reader`` open the file.
Chunks are LZ4-compressed (cheap enough for the executor thread).
"""

from __future__ import annotations

import os
import re
import sys
import threading
import time
from pathlib import Path

from pmnav_bt.errors import PmNavError

_PRIMITIVES = {
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
    "int32", "uint32", "int64", "uint64", "string", "wstring",
}  # fmt: skip
_SEPARATOR = "=" * 80


class RecordingError(PmNavError):
    """The recording cannot be written (a bad path, a message type without a definition)."""


def _share_dirs() -> list[Path]:
    """Where .msg files live: each AMENT_PREFIX_PATH entry's share/, then this prefix's
    (the ROS wheels install their definitions into <venv>/share)."""
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [Path(p) / "share" for p in [*prefixes, sys.prefix]]


def _msg_text(pkg: str, name: str) -> str:
    for share in _share_dirs():
        path = share / pkg / "msg" / f"{name}.msg"
        if path.is_file():
            return path.read_text(encoding="utf-8")
    raise RecordingError(f"no message definition {pkg}/msg/{name}.msg under {_share_dirs()}")


def _field_types(text: str, pkg: str) -> list[tuple[str, str]]:
    """The (package, name) of each non-primitive field type in a .msg text."""
    out = []
    for line in text.splitlines():
        tokens = line.split("#", 1)[0].split()
        if len(tokens) < 2:
            continue
        kind = re.sub(r"(<=\d+)?(\[[^\]]*\])?$", "", tokens[0])
        if kind in _PRIMITIVES:
            continue
        dep_pkg, _, dep = kind.rpartition("/")
        out.append((dep_pkg.removesuffix("/msg") or pkg, dep))
    return out


def schema_text(type_name: str) -> str:
    """The ros2msg schema of ``pkg/msg/Name``: its .msg, then each dependency once."""
    pkg, _, name = type_name.replace("/msg/", "/").partition("/")
    text = _msg_text(pkg, name)
    parts, seen = [text.rstrip("\n")], {(pkg, name)}
    todo = _field_types(text, pkg)
    while todo:
        dep = todo.pop(0)
        if dep in seen:
            continue
        seen.add(dep)
        dep_text = _msg_text(*dep)
        parts.append(f"{_SEPARATOR}\nMSG: {dep[0]}/{dep[1]}\n{dep_text.rstrip()}")
        todo += _field_types(dep_text, dep[0])
    return "\n".join(parts) + "\n"


def type_name(msg_type) -> str:
    """``sensor_msgs/msg/Image`` for the class ``sensor_msgs.msg.Image``."""
    module = msg_type.__module__.split(".")
    return f"{module[0]}/msg/{msg_type.__name__}"


class McapRecorder:
    """Records ``topics`` [(name, message class, QoS)] of ``node`` into ``path``."""

    def __init__(self, node, path: str | Path, topics: list[tuple[str, type, object]]) -> None:
        from mcap.writer import CompressionType, Writer

        self.path = Path(path)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = open(self.path, "wb")  # noqa: SIM115 - closed in close()
        except OSError as err:
            raise RecordingError(f"--record {path}: {err.strerror}") from None
        self._writer = Writer(self._file, compression=CompressionType.LZ4)
        self._writer.start(profile="ros2", library="pmnav-bt")
        self._lock = threading.Lock()
        self._closed = False
        self.counts: dict[str, int] = {}
        schemas: dict[str, int] = {}
        self._subs = []
        for topic, msg_type, qos in topics:
            kind = type_name(msg_type)
            if kind not in schemas:
                schemas[kind] = self._writer.register_schema(
                    name=kind, encoding="ros2msg", data=schema_text(kind).encode()
                )
            resolved = node.resolve_topic_name(topic)
            channel = self._writer.register_channel(
                topic=resolved, message_encoding="cdr", schema_id=schemas[kind]
            )
            self.counts[resolved] = 0
            self._subs.append(
                node.create_subscription(
                    msg_type, topic, self._callback(resolved, channel), qos, raw=True
                )
            )

    def _callback(self, topic: str, channel: int):
        def write(data: bytes) -> None:
            now = time.time_ns()
            with self._lock:
                if self._closed:
                    return
                seq = self.counts[topic]
                self._writer.add_message(
                    channel_id=channel, log_time=now, data=data, publish_time=now, sequence=seq
                )
                self.counts[topic] = seq + 1

        return write

    def close(self) -> None:
        """Write the summary and close the file. Idempotent."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            self._writer.finish()
            self._file.close()
