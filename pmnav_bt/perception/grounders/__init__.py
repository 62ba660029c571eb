"""Grounder back ends (the ``Grounder`` seam): ``sim_gt`` reads the simulator's labels (oracle),
``ocr`` reads signs, ``gdino_sam`` grounds text with GroundingDINO + SAM."""
