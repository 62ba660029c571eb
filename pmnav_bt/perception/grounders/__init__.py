"""Grounder back ends (the ``Grounder`` seam): ``ocr`` reads signs, ``gdino_sam`` grounds text."""
