"""Experiments: the one layer that joins the simulator, the tree and the metrics."""
