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
    CANCELLED = "CANCELLED"


@dataclass(frozen=True)
class Failure:
    code: FailureCode
    message: str

    def __str__(self) -> str:
        return f"{self.code.value}: {self.message}"
