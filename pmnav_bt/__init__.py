"""PM-Nav BT: priori-map guided navigation in functional buildings, as a behaviour tree.

The core package holds the building model, the semantic priori-map, planners,
perception back ends and the CLI. The sibling packages ``pmnav_bt.behaviours``,
``pmnav_bt.trees``, ``pmnav_bt.sim`` and ``pmnav_bt.hardware`` build on it.
"""

__version__ = "0.1.0"
