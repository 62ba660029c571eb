"""Perception back ends behind the seams: grounders, coarse direction, refiners, corner checks."""
