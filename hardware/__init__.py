"""pmnav_bt.hardware: PM-Nav on ROS 2 (docs/ros2.md).

- ``create3``: the iRobot Create 3 as a ``Base`` over rclpy (cmd_vel heartbeat, odom,
  camera, safety stops); ``hazards``: its ``hazard_detection`` topic (bumps, cliffs,
  stalls: the messages, and the motions a hazard forbids); ``clock``: ``RosClock``;
- ``node``: the ``pmnav-ros`` controller node, wiring ``readiness`` (fresh sensors before a
  goal), ``requests`` (goals from any front end, feedback), ``action_server`` (the
  ``navigate_to_room`` action), ``diagnostics`` (/diagnostics), ``params`` (validation,
  --help) and ``recorder`` (--record FILE.mcap); ``goal``: ``pmnav-ros-goal``;
  ``launcher``: ``pmnav-launch``, what launch/pmnav.launch.py does without launch_ros;
- ``sim_create3``: ``pmnav-sim-create3``, the pybullet simulator behind the robot's topics;
- lifts over Open-RMF's lift protocol: ``rmf_lift`` (topics, rmf_lift_msgs conversions),
  ``lift_client`` (``RosLiftClient``, a ``seams.Lift``; ``pmnav-ros -p lifts:=true``),
  ``lift_bank`` (simulated lifts in time) and ``sim_lift_node`` (``pmnav-sim-lift``);
- ``env``, ``runtime``, ``qos``, ``messages``, ``testing``: environment, executor, QoS,
  message conversions, subprocess helpers.

Nothing here imports rclpy at import time; the functions that need it import it.
"""
