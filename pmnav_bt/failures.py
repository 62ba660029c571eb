"""Why a run failed: Nav2-style error codes with a message for people."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

from pmnav_bt.errors import (
    BackendError,
    ConfigError,
    PlanningError,
    PmNavError,
    SensorError,
    UnknownNameError,
    VlmError,
)


class FailureCode(str, Enum):
    LOCALIZATION_FAILED = "LOCALIZATION_FAILED"  # fewer than two landmarks after exploring
    INVALID_GOAL = "INVALID_GOAL"  # the goal names no room of the map
    PLANNING_FAILED = "PLANNING_FAILED"  # no route from the estimated pose to the goal
    TARGET_NOT_FOUND = "TARGET_NOT_FOUND"  # a plan landmark was not found after re-search/replan
    BLOCKED = "BLOCKED"  # the way is physically blocked
    DOOR_CLOSED = "DOOR_CLOSED"  # a door across the route (a fire door) is closed
    LIFT_NOT_COMING = "LIFT_NOT_COMING"  # the lift did not come, or its door did not open, in time
    LIFT_FULL = "LIFT_FULL"  # the lift came full, every time the robot waited for it
    WRONG_LEVEL = "WRONG_LEVEL"  # the signs read on leaving the lift belong to another level
    BUDGET_EXCEEDED = "BUDGET_EXCEEDED"  # the action budget ran out
    TIMEOUT = "TIMEOUT"  # a step took longer than its clock budget
    SENSOR_TIMEOUT = "SENSOR_TIMEOUT"  # no camera frames or odometry
    BASE_FAULT = "BASE_FAULT"  # the body reports it cannot move
    STOPPED_AWAY = "STOPPED_AWAY"  # the tree arrived, but the robot stopped too far from the door
    CANCELLED = "CANCELLED"  # the user cancelled the goal
    VLM_ERROR = "VLM_ERROR"  # the VLM server failed, timed out or gave no usable answer
    BACKEND_ERROR = "BACKEND_ERROR"  # a back end cannot run (missing weights, no labels)
    INTERNAL_ERROR = "INTERNAL_ERROR"  # a bug: an unexpected exception, with its message


@dataclass(frozen=True)
class Failure:
    """Why something failed. ``cause``: the first, root-cause failure when a recovery that
    followed it failed too (the run reports both)."""

    code: FailureCode
    message: str
    cause: Failure | None = None

    def __str__(self) -> str:
        text = f"{self.code.value}: {self.message}"
        return f"{text} (after {self.cause})" if self.cause is not None else text


# The code for each of the project's exception types (the first match, most specific first).
_CODES: tuple[tuple[type[PmNavError], FailureCode], ...] = (
    (SensorError, FailureCode.SENSOR_TIMEOUT),
    (VlmError, FailureCode.VLM_ERROR),
    (PlanningError, FailureCode.PLANNING_FAILED),
    (UnknownNameError, FailureCode.PLANNING_FAILED),
    (BackendError, FailureCode.BACKEND_ERROR),
    (ConfigError, FailureCode.BACKEND_ERROR),
)


def failure_from(err: BaseException, doing: str = "") -> Failure:
    """The Failure an exception stands for: the project's own errors by type, anything else
    an INTERNAL_ERROR (a bug) with "Type: message". ``doing`` says what was under way."""
    where = f"{doing}: " if doing else ""
    code = next((c for t, c in _CODES if isinstance(err, t)), None)
    if code is not None:
        return Failure(code, f"{where}{err}")
    return Failure(FailureCode.INTERNAL_ERROR, f"{where}{type(err).__name__}: {err}")


def root_cause(failure: Failure | None) -> Failure | None:
    """The first failure of a chain (the one that started the recoveries)."""
    while failure is not None and failure.cause is not None:
        failure = failure.cause
    return failure
