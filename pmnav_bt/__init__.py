"""PM-Nav BT: priori-map guided navigation in functional buildings, as a behaviour tree.

The core package holds the seams and the back-end registry, the building model, the
semantic priori-map, planners, perception back ends, test doubles and the core CLI
commands. The sibling packages ``pmnav_bt.behaviours``, ``pmnav_bt.trees``,
``pmnav_bt.sim`` and ``pmnav_bt.hardware`` build on it; ``pmnav_bt.experiments`` joins
simulator, tree and metrics (evaluation, ``pmnav sim``, the ``pmnav`` entry point). The
core imports none of them (``tests/project/test_layering.py``).
"""

__version__ = "0.1.0"
