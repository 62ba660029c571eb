"""Why a run failed: Nav2-style error codes with a message for people."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class FailureCode(str, Enum):
    LOCALIZATION_FAILED = "LOCALIZATION_FAILED"  # fewer than two landmarks after exploring
    INVALID_GOAL = "INVALID_GOAL"  # the goal names no room of the map
    PLANNING_FAILED = "PLANNING_FAILED"  # no route from the estimated pose to the goal
    TARGET_NOT_FOUND = "TARGET_NOT_FOUND"  # a plan landmark was not found after re-search/replan
    BLOCKED = "BLOCKED"  # the way is physically blocked
    BUDGET_EXCEEDED = "BUDGET_EXCEEDED"  # the action budget ran out
    TIMEOUT = "TIMEOUT"  # a step took longer than its clock budget
    SENSOR_TIMEOUT = "SENSOR_TIMEOUT"  # no camera frames or odometry
    BASE_FAULT = "BASE_FAULT"  # the body reports it cannot move
    STOPPED_AWAY = "STOPPED_AWAY"  # the tree arrived, but the robot stopped too far from the door
    CANCELLED = "CANCELLED"  # the user cancelled the goal
    VLM_ERROR = "VLM_ERROR"  # the VLM server failed, timed out or gave no usable answer
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
