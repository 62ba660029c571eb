"""``pmnav-sim-lift``: simulated lifts behind Open-RMF's lift topics, like an RMF lift adapter.

A ``LiftBank`` (``hardware/lift_bank.py``: sessions, seeded call delays, the ride time per
level, the door's travel and dwell; by default a hospital bed lift's timings,
``pmnav_bt/lift_timing.py``) driven by the wall clock:

- in ``/lift_requests`` (rmf_lift_msgs/LiftRequest): AGV or human mode asks a lift to a
  floor with its door open or closed there; REQUEST_END_SESSION releases it. A lift held
  by another session does not answer until that session ends; requests for lifts or
  floors it does not have are logged and dropped;
- out ``/lift_states`` (rmf_lift_msgs/LiftState): every lift's state at ``publish_hz``
  (2 Hz, as RMF's simulated lifts) and at once when it changes.

The lifts: a site's (``-p site:=hospital_2l``: each lift serves the levels of its lobbies,
lowest first by elevation), or ``lifts`` that all serve ``levels``. Run: ``pmnav-sim-lift
--ros-args -p site:=hospital_2l`` (or ``python -m pmnav_bt.hardware.sim_lift_node``);
``--help`` lists the parameters.
"""

from __future__ import annotations

import sys

from pmnav_bt.errors import PmNavError
from pmnav_bt.lift_timing import BED_LIFT as LIFT

PARAMETERS = {
    "site": ("", "site file or built-in site whose lifts to simulate; empty: lifts and levels"),
    "lifts": ("lift1", "without a site: the lifts' names, comma-separated (LiftRequest.lift_name)"),
    "levels": ("L1,L2", "without a site: the levels every lift serves, lowest first"),
    "start_level": ("", "where the cabins stand at the start; empty: the lowest level"),
    "ride_s_per_level": (LIFT.ride_s_per_level, "seconds from one level to the next"),
    "door_s": (LIFT.door_s, "seconds the door takes to open, or to close"),
    "dwell_s": (LIFT.dwell_s, "seconds the door stays open after a session ends"),
    "call_delay_s": (LIFT.call_delay_s, "a granted call waits a seeded delay up to this (s)"),
    "seed": (0, "seed of the call delays"),
    "publish_hz": (2.0, "LiftState rate (a state also goes out on every change)"),
    "step_hz": (20.0, "how often the lifts' motion is advanced"),
}


TIMING_PARAMETERS = ("ride_s_per_level", "door_s", "dwell_s", "call_delay_s")  # LiftTiming's


def _names(text: str, what: str) -> list[str]:
    names = [s.strip() for s in str(text).split(",") if s.strip()]
    if not names:
        raise PmNavError(f"parameter {what!r}: expected comma-separated names, got {text!r}")
    return names


def bank_lifts(p: dict, given: set[str]) -> dict[str, list[str]]:
    """Each lift's levels, lowest first: the site's lifts (the levels of their lobbies, by
    elevation), or every one of ``lifts`` serving ``levels``. ``given``: the parameters
    set on the command line (a site names its own lifts: ``lifts``/``levels`` beside it
    are an error)."""
    if not p["site"]:
        levels = _names(p["levels"], "levels")
        return {name: levels for name in _names(p["lifts"], "lifts")}
    from pmnav_bt.map.site import load_site

    both = sorted(given & {"lifts", "levels"})
    if both:
        raise PmNavError(f"parameter 'site' names the lifts and their levels; leave out {both}")
    site = load_site(p["site"])
    if not site.lifts:
        raise PmNavError(f"parameter 'site': {site.name} has no lifts")
    return {lift.id: sorted(lift.levels, key=site.rank) for lift in site.lifts}


class SimLiftNode:
    """The node's logic on an rclpy ``node``."""

    def __init__(self, node) -> None:
        from pmnav_bt.hardware import qos, rmf_lift
        from pmnav_bt.hardware.lift_bank import LiftBank
        from pmnav_bt.hardware.node import declare_parameters
        from pmnav_bt.lift_timing import LiftTiming

        request_type, state_type = rmf_lift.messages()
        self.node = node
        self.log = node.get_logger()
        self.p = p = declare_parameters(node, PARAMETERS)
        for name in ("publish_hz", "step_hz"):
            if not 0.1 <= p[name] <= 1000.0:
                raise PmNavError(f"parameter {name!r}: expected 0.1 to 1000, got {p[name]:g}")
        self._Request = request_type
        clock = node.get_clock()
        lifts = bank_lifts(p, set(getattr(node, "_parameter_overrides", {}) or {}))
        self.bank = LiftBank(
            lifts,
            start_level=str(p["start_level"]).strip(),
            timing=LiftTiming(**{k: float(p[k]) for k in TIMING_PARAMETERS}),
            seed=int(p["seed"]),
            clock=lambda: clock.now().nanoseconds * 1e-9,
            log=self.log.info,
        )
        self._sent: dict[str, tuple] = {}
        self.pub = node.create_publisher(state_type, rmf_lift.STATES_TOPIC, qos.lift_states())
        # volatile, as RMF's lifts subscribe: an old request is not replayed to a new lift
        node.create_subscription(
            request_type, rmf_lift.REQUESTS_TOPIC, self._on_request, qos.events(100)
        )
        node.create_timer(1.0 / float(p["step_hz"]), self._publish_changed)
        node.create_timer(1.0 / float(p["publish_hz"]), self._publish_all)
        served = "; ".join(f"{name} ({', '.join(levels)})" for name, levels in lifts.items())
        self.log.info(
            f"simulated lifts {served} on {rmf_lift.REQUESTS_TOPIC} -> {rmf_lift.STATES_TOPIC}"
        )

    def _on_request(self, msg) -> None:
        if msg.lift_name not in self.bank.lifts:
            return  # another adapter's lift
        if msg.request_type == self._Request.REQUEST_END_SESSION:
            self.bank.release(msg.lift_name, msg.session_id)
        else:  # AGV or human mode: this simulation drives the door as the request says
            door_open = msg.door_state == self._Request.DOOR_OPEN
            self.bank.request(msg.lift_name, msg.destination_floor, msg.session_id, door_open)
        self._publish_changed()

    def _publish_changed(self) -> None:
        self._publish(only_changed=True)

    def _publish_all(self) -> None:
        self._publish(only_changed=False)

    def _publish(self, only_changed: bool) -> None:
        from pmnav_bt.hardware import rmf_lift

        stamp = self.node.get_clock().now().to_msg()
        for lift in self.bank.lifts:
            s = self.bank.state(lift)
            key = (s.current_level, s.destination_level, s.door, s.motion, s.session)
            if only_changed and self._sent.get(lift) == key:
                continue
            self._sent[lift] = key
            self.pub.publish(rmf_lift.state_message(s, stamp))


def main(argv: list[str] | None = None) -> None:
    """Console script ``pmnav-sim-lift``: ``pmnav-sim-lift --ros-args -p site:=hospital_2l``
    or ``-p lifts:=lift1,lift2 -p levels:=L1,L2,L3``."""
    from pmnav_bt.hardware.params import usage, wants_help
    from pmnav_bt.hardware.runtime import run_node

    args = list(sys.argv if argv is None else argv)
    if wants_help(args):
        example = "pmnav-sim-lift --ros-args -p site:=hospital_2l -p call_delay_s:=5"
        print(usage("pmnav-sim-lift", (__doc__ or "").split("\n\n")[0], PARAMETERS, example))
        sys.exit(0)
    run_node("pmnav-sim-lift", "sim_lift", args, lambda node, _runtime: SimLiftNode(node))


if __name__ == "__main__":  # pragma: no cover
    main()
