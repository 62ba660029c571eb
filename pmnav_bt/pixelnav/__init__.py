"""PixelNav: a pixel-goal policy (Cai et al., CVPR 2024) trained in our simulator.

Stages, one module each: ``data`` (expert rollouts to goal pixels, on generated
buildings), ``model`` (the torch network), ``train`` (imitation), ``policy`` (the
closed-loop back end the tree uses), ``skill_eval`` (the skill on its own). Only
``policy`` and ``model`` are needed at run time; torch is imported there, never here.
"""
