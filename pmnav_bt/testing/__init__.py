"""Test doubles for the seams: run behaviours and trees without a simulator or a robot."""
