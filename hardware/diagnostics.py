"""The controller's health as ``diagnostic_msgs/DiagnosticArray`` on ``/diagnostics``.

One DiagnosticStatus, ``pmnav: controller`` (hardware_id: the building): OK when ready
and idle or running; WARN while idle or waiting for an input that is missing (the
message names it); ERROR on a base fault during a run. The key/values carry the state,
the goal, sensor ages and the cmd_vel period statistics, as ``rqt_runtime_monitor`` and
Foxglove show them.
"""

from __future__ import annotations

from typing import Any

NAME = "pmnav: controller"


def level_and_message(status: dict[str, Any]) -> tuple[int, str]:
    """(DiagnosticStatus level, message) for a status dict of the controller."""
    from diagnostic_msgs.msg import DiagnosticStatus

    waiting = status.get("waiting_for_sensors") or status.get("state") != "running"
    if status.get("missing") and waiting:
        return DiagnosticStatus.WARN, "not ready: " + "; ".join(status["missing"])
    if status.get("state") == "running" and status.get("fault"):
        return DiagnosticStatus.ERROR, f"running {status.get('goal')!r}: {status['fault']}"
    if status.get("state") == "running":
        return DiagnosticStatus.OK, f"running goal {status.get('goal')!r}"
    return DiagnosticStatus.OK, "ready"


def diagnostic_array(status: dict[str, Any], stamp, hardware_id: str):
    """The status dict as a DiagnosticArray (nested values flattened as ``a.b``)."""
    from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

    level, message = level_and_message(status)
    values = []
    for key, value in status.items():
        if isinstance(value, dict):
            values += [KeyValue(key=f"{key}.{k}", value=str(v)) for k, v in value.items()]
        elif isinstance(value, list):
            values.append(KeyValue(key=key, value="; ".join(map(str, value))))
        else:
            values.append(KeyValue(key=key, value="" if value is None else str(value)))
    st = DiagnosticStatus(
        level=level, name=NAME, message=message, hardware_id=hardware_id, values=values
    )
    arr = DiagnosticArray()
    arr.header.stamp = stamp
    arr.status = [st]
    return arr
