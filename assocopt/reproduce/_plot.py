"""The plotting steps every paper reproduction's figures share: matplotlib on the
headless Agg back end (figures are optional: without matplotlib a reproduction writes
none), and one way to lay out, write and close a figure."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

__all__ = ["pyplot", "save", "draw_all"]

#: Resolution of every reproduction figure.
DPI = 110


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg back end, or ``None`` without matplotlib."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    return plt


def save(fig: Any, out: str | Path, name: str, *,
         rect: tuple[float, float, float, float] | None = None, **savefig: Any) -> str:
    """Lay ``fig`` out (within ``rect`` of the figure when given), write it to
    ``out/name`` at :data:`DPI` (``savefig`` options passed on) and close it; returns
    ``name``, the entry of the summary's figure list."""
    import matplotlib.pyplot as plt
    fig.tight_layout(rect=rect)
    fig.savefig(Path(out) / name, dpi=DPI, **savefig)
    plt.close(fig)
    return name


def draw_all(summary: Mapping[str, Any], out: str | Path,
             drawers: Sequence[Callable[..., str | None]], *args: Any) -> list[str]:
    """Call each ``drawer(plt, summary, out, *args)``, which returns the name of the
    figure it wrote or ``None`` when the summary has nothing for it; returns the names
    written, [] without matplotlib."""
    plt = pyplot()
    if plt is None:
        return []
    out = Path(out)
    return [name for fn in drawers if (name := fn(plt, summary, out, *args))]
