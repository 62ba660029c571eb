"""QoS profiles for the Create 3 topics and PM-Nav's own.

- ``sensor()``: best effort, keep last 5, volatile (rclpy's ``qos_profile_sensor_data``).
  A best-effort subscriber matches both best-effort and reliable publishers, so it is
  the right choice for odometry and cameras whatever the driver publishes with.
- ``hazards()``: what the Create 3 publishes ``hazard_detection`` with: sensor data (keep
  last 5, volatile) but reliable (iRobot's ``hazards_vector_publisher``:
  ``SensorDataQoS().reliable()``). The body subscribes with ``sensor()``, which matches
  it and a best-effort publisher alike; the simulated Create 3 publishes with this.
- ``command()``: reliable, keep last 1: ``cmd_vel``. A reliable publisher matches the
  Create 3's subscriber (reliable) as well as best-effort ones; only the newest
  command matters.
- ``latched()``: reliable, transient local, keep last 1: things a late subscriber
  (RViz, a test) needs once: the plan, the map markers, segmentation labels,
  the tree's structure.
- ``events()``: reliable, volatile, keep last 10: goals, results, status, snapshots.
- ``lift_requests()``: reliable, transient local, keep last 100: Open-RMF's lift requests,
  as its fleet adapter and lift supervisor publish them (a lift adapter subscribes
  volatile, which matches); ``lift_states()``: reliable, volatile, keep last 100, as
  RMF's lifts publish their states and its adapters read them.
"""

from __future__ import annotations

from pmnav_bt.hardware.env import import_rclpy


def _qos():
    import_rclpy()
    from rclpy import qos

    return qos


def sensor():
    return _qos().qos_profile_sensor_data


def hazards():
    return _reliable(depth=5, transient_local=False)


def command():
    return _reliable(depth=1, transient_local=False)


def latched():
    return _reliable(depth=1, transient_local=True)


def events(depth: int = 10):
    return _reliable(depth=depth, transient_local=False)


def lift_requests():
    return _reliable(depth=100, transient_local=True)


def lift_states():
    return _reliable(depth=100, transient_local=False)


def _reliable(depth: int, transient_local: bool):
    """Reliable, keep last ``depth``; transient local (a late subscriber gets the last
    messages) or volatile."""
    q = _qos()
    return q.QoSProfile(
        depth=depth,
        history=q.HistoryPolicy.KEEP_LAST,
        reliability=q.ReliabilityPolicy.RELIABLE,
        durability=(
            q.DurabilityPolicy.TRANSIENT_LOCAL if transient_local else q.DurabilityPolicy.VOLATILE
        ),
    )
