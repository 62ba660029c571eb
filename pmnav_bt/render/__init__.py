"""Pictures: the annotated priori-map, trajectory plots, the belief's steps."""


def headless_pyplot():
    """matplotlib's pyplot on the Agg back end (no display), imported when first drawn."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt
