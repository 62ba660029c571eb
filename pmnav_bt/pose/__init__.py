"""Where the robot is when landmarks are scarce: what the map says is readable where, a
belief over corridor positions, pose correction, heading from walls, snapping to corridors."""
