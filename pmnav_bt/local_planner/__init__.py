"""The local planner between a drive's goal and the wheels: a rolling costmap from depth
(``costmap``), the dynamic window approach over it (``dwa``), and the seam a drive steers
through, with its variants by name (``steering``: ``direct``, ``dwa``)."""
