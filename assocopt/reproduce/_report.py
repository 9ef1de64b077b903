"""The report files every paper reproduction writes, written the same way for each, and
the table cells and lines their pages share."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

from ..io.writers import write_json_atomically, write_text_atomically

__all__ = ["write_report", "mean_ci", "wall_time_line"]

#: z of the two-sided 95 % normal interval the tables quote.
Z95 = 1.96


def write_report(out: Path, summary: dict[str, Any], render_tables: Callable[[dict], str],
                 make_figures: Callable[[dict, Path], list[str]],
                 echo: Callable[[str], Any] = print) -> dict[str, Any]:
    """Render the tables, draw the figures, write ``summary.json`` and ``tables.md``
    atomically into ``out``, print the tables with ``echo``; returns ``summary``."""
    text = render_tables(summary)
    summary["figures"] = make_figures(summary, out)
    write_json_atomically(out / "summary.json", summary, indent=1)
    write_text_atomically(out / "tables.md", text)
    echo(text)
    return summary


def mean_ci(v: tuple | None, digits: int) -> str:
    """A ``(value, runs, stderr)`` entry as ``mean ± 95 % half-width`` with ``digits``
    decimals (the mean alone without a standard error; a dash for no entry)."""
    if v is None:
        return "—"
    value, _, se = v
    return (f"{value:.{digits}f} ± {Z95 * se:.{digits}f}" if se is not None
            else f"{value:.{digits}f}")


def wall_time_line(summary: dict[str, Any]) -> list[str]:
    """The tables' closing line: the wall time of the run that wrote ``summary`` (none
    when it records no ``wall_s``)."""
    if "wall_s" not in summary:
        return []
    return [f"Wall time of this run: {summary['wall_s']:.0f} s "
            f"({summary['workers']} worker(s))."]
