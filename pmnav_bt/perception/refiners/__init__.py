"""Refiner back ends (the ``Refiner`` seam): ``geometric`` measures bearing and range."""
