"""Evaluation: metrics (SR, SPL, soft SPL, SDF), tiers, episodes as data. No pybullet."""
