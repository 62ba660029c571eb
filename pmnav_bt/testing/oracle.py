"""The oracle grounder for tests that need speed or determinism, set explicitly.

The default grounder is the real stack (``ocr``); tests that run whole episodes to check
the tree, not perception, choose the simulator's labels (``sim_gt``) by name.
"""

from __future__ import annotations

from pmnav_bt.config import Config, load_config

ORACLE = "grounder.backend=sim_gt"
ORACLE_SET = ("--set", ORACLE)  # for CLI argument lists


def oracle_config(*overrides: str) -> Config:
    """The default config with the oracle grounder, then ``overrides``."""
    return load_config(None, [ORACLE, *overrides])
