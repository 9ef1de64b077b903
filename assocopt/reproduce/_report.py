"""The report files every paper reproduction writes, written the same way for each."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable

from ..io.writers import write_json_atomically, write_text_atomically

__all__ = ["write_report"]


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
