"""Matplotlib without a display, and PNGs that reruns reproduce byte for byte."""

from __future__ import annotations

import io
import os
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def pyplot() -> ModuleType:
    """``matplotlib.pyplot`` on the Agg backend (imported on first use: it is slow to import). rjcad renders to
    files: a bad ``MPLBACKEND`` is overridden; where Matplotlib's config and cache folders cannot be made (an
    unwritable HOME) it gets a private one, removed at exit, instead of warning on stderr."""
    import sys

    if "matplotlib" not in sys.modules:
        os.environ["MPLBACKEND"] = "Agg"
        if not os.environ.get("MPLCONFIGDIR") and not _matplotlib_dirs_made():
            import atexit
            import shutil
            import tempfile

            private = tempfile.mkdtemp(prefix="rjcad-mpl-")
            atexit.register(shutil.rmtree, private, True)
            os.environ["MPLCONFIGDIR"] = private
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _matplotlib_dirs_made() -> bool:
    """Make Matplotlib's config and cache folders (XDG, or under HOME), as it would; False if one cannot be."""
    home = os.path.expanduser("~")
    dirs = (
        os.path.join(os.environ.get("XDG_CONFIG_HOME") or os.path.join(home, ".config"), "matplotlib"),
        os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.join(home, ".cache"), "matplotlib"),
    )
    try:
        for d in dirs:
            os.makedirs(d, exist_ok=True)
            if not os.access(d, os.W_OK):
                return False
    except OSError:
        return False
    return True


def png_bytes(fig: Figure, dpi: float | str = 100) -> bytes:
    """PNG of ``fig`` without the 'Software' version chunk, so reruns are byte-identical; closes ``fig``."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, metadata={"Software": None})
    pyplot().close(fig)
    return buf.getvalue()


def save_png(fig: Figure, path: str | os.PathLike[str], dpi: float | str = 100) -> Path:
    """Write ``fig`` as a PNG (see ``png_bytes``) atomically; closes ``fig``."""
    from rjcad.io.config import write_atomic

    return write_atomic(path, png_bytes(fig, dpi))


def axes_png(path: str | os.PathLike[str], draw: Callable[[Any], None]) -> Path:
    """Write a 7 × 5 in, 100 dpi PNG of one axes that ``draw(ax)`` fills (a light grid added)."""
    fig, ax = pyplot().subplots(figsize=(7, 5))
    draw(ax)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return save_png(fig, path, dpi=100)
