"""Localization, one stage: where the robot is on the priori-map.

- ``landmark_fix``: two signs read fix the pose (``fix_pose``), and the shift that puts
  signs read close together on their map places (``sign_shift``);
- ``visibility``: what the map says is readable where, on a lattice along the corridors;
- ``belief``: the corridor belief (``CorridorBelief``, ``Glimpse``) when signs are
  scarce, composed of ``hypotheses`` (poses and their motion update), ``evidence`` (one
  module per kind), ``lead`` and ``telling`` (where to drive or look next) and
  ``lookahead`` (the expected trip from a telling place);
- ``correction``, ``odometry``, ``walls``, ``snap``: keeping the pose once fixed (heading
  from walls, odometry calibration, snapping to corridors).
"""
