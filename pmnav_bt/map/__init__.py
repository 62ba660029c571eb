"""The building model: building files, floor plans, the priori-map, generated buildings."""
