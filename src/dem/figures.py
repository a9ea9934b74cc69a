"""Matplotlib without a display, and figures saved atomically (a killed run never leaves a
truncated PNG)."""

import os

from .atomic import replacing


def pyplot():
    """matplotlib.pyplot on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def save_figure(figure, path, dpi=120):
    """Lay out ``figure``, write it to ``path`` (PNG unless the extension says otherwise),
    creating the folder, atomically; close it; return ``path``."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    figure.tight_layout()
    extension = os.path.splitext(path)[1].lstrip(".") or "png"
    with replacing(path) as temporary:
        figure.savefig(temporary, dpi=dpi, format=extension)
    pyplot().close(figure)
    return path
