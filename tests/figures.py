"""The plots as the tests look at them: matplotlib without a display, the pocket panels of a
slow scan drawn into a figure of their own, and a PNG file's signature and size."""

import struct
from contextlib import contextmanager
from pathlib import Path

__all__ = ["PNG_SIGNATURE", "png_size", "pyplot", "pocket_panels"]

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path):
    """(width, height) in pixels, from the PNG's IHDR."""
    data = Path(path).read_bytes()
    assert data.startswith(PNG_SIGNATURE)
    return struct.unpack(">II", data[16:24])


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (no display)."""
    import warnings

    import matplotlib

    matplotlib.use("Agg")
    with warnings.catch_warnings():  # Debian's mpl_toolkits beside PyPI's: no 3D plots here
        warnings.simplefilter("ignore", UserWarning)
        import matplotlib.pyplot as plt
    return plt


@contextmanager
def pocket_panels(result):
    """The pocket panels of a scan's ``result`` drawn into a new figure: ``(axes, drawn)``, the
    panels and what ``draw_pockets`` reported drawing; the figure is closed afterwards."""
    plt = pyplot()  # before the plots' module imports matplotlib on its own terms
    from waferscan.plots.pockets import draw_pockets

    figure = plt.figure()
    drawn = []
    try:
        yield draw_pockets(figure, figure.add_gridspec(1, 1)[0, 0], result, drawn), drawn
    finally:
        plt.close(figure)
