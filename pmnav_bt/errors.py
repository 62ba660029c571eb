"""The project's own exception types: every error a user can cause is one of these."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass


class PmNavError(Exception):
    """Base class of errors a user can cause; the CLI prints them in one line."""

    def __str__(self) -> str:
        # One line whatever user text (a file name with a newline, say) the message quotes.
        return " ".join(super().__str__().split())


@dataclass(frozen=True)
class Problem:
    """One problem found in a file: the field path (``rooms[3].door``) and what is wrong."""

    field: str
    message: str

    def __str__(self) -> str:
        return f"{self.field}: {self.message}" if self.field else self.message


class BuildingFileError(PmNavError):
    """A building file could not be read or is invalid; ``problems`` lists every problem."""

    def __init__(self, path: str, problems: Sequence[Problem]):
        self.path = str(path)
        self.problems = list(problems)
        super().__init__(self.summary())

    def summary(self) -> str:
        """One line: the first problem and how many more there are."""
        first = self.problems[0] if self.problems else Problem("", "invalid building file")
        more = len(self.problems) - 1
        tail = f" (and {more} more; run 'pmnav validate {self.path}' to list all)" if more else ""
        return f"{self.path}: {first}{tail}"

    def lines(self) -> list[str]:
        """Every problem, one line each, prefixed by the file."""
        return [f"{self.path}: {p}" for p in self.problems]

    def listing(self) -> list[str]:
        """What ``pmnav validate`` prints: every problem's line, then their count."""
        return [*self.lines(), f"{len(self.problems)} problem(s)"]


class UnknownNameError(PmNavError):
    """A room, landmark, segment or waypoint name that is unknown or ambiguous."""

    def __init__(self, message: str, candidates: Sequence[str] = ()):
        self.candidates = list(candidates)
        super().__init__(message)


class PlanningError(PmNavError):
    """No plan exists (for example, the goal is not reachable from the start)."""


class ConfigError(PmNavError):
    """A configuration file or value is invalid."""


class SensorError(PmNavError):
    """A sensor gave no data in time (no camera frame, no odometry)."""


class VlmError(PmNavError):
    """A VLM server could not be reached, failed, timed out or answered unusably."""


class BackendError(PmNavError):
    """A perception or planning back end cannot be built or run (missing weights, a
    simulator-only back end on a robot)."""
