"""Matplotlib without a display, and PNGs that reruns reproduce byte for byte."""

from __future__ import annotations

import io
import os
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def pyplot() -> ModuleType:
    """``matplotlib.pyplot`` on the Agg backend (imported on first use: it is slow to import)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


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
