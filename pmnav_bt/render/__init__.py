"""Pictures: the annotated priori-map and trajectory plots."""
