"""Grounder back ends (the ``Grounder`` seam): ``sim_gt`` reads the simulator's labels."""
