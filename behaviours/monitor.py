"""The mission monitor: counts actions against the budget and watches the body."""

from __future__ import annotations

from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.failures import FailureCode
from pmnav_bt.seams import MotionStatus


class Monitor(PmNavBehaviour):
    """RUNNING while the mission may go on; FAILURE when the action budget is spent
    (BUDGET_EXCEEDED), a body with the optional ``fault()`` hook reports one (its
    Failure, e.g. SENSOR_TIMEOUT for a silent camera) or the body faults (BASE_FAULT).
    The budget is the context's and the actions the mission was granted on the way
    (``actions_granted``: a boarding let go because the lift came full,
    ``behaviours/lift.py`` ``BoardAgainAllowed``).

    Reads ``actions_granted``; writes ``failure`` only."""

    READS = ("actions_granted",)

    def update(self) -> Status:
        base = self.ctx.base
        fault = getattr(base, "fault", None)  # optional: Failure | None (hardware bases)
        failure = fault() if callable(fault) else None
        if failure is not None:
            base.stop()
            return self.fail(failure.code, failure.message)
        self.ctx.odometer.update(base.pose())
        used = self.ctx.odometer.actions
        budget = self.ctx.budget_actions + (self.get("actions_granted") or 0)
        if used > budget:
            base.stop()
            return self.fail(FailureCode.BUDGET_EXCEEDED, f"{used} actions used of {budget}")
        if base.motion_status() == MotionStatus.FAULT:
            base.stop()
            return self.fail(FailureCode.BASE_FAULT, "the base reports a fault")
        self.feedback_message = f"{used}/{budget} actions"
        return Status.RUNNING
