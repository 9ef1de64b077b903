"""One progress display for every long loop (experiment runs, ``assocopt compare``).

:class:`Progress` shows a tqdm bar when tqdm is installed, otherwise a one-line
counter rewritten in place on the stream (``label: n/total units (t s) note``), and
nothing at all when disabled.
"""

from __future__ import annotations

import sys
import time
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """Counter of ``total`` steps, starting at ``initial``; call :meth:`close` at the end."""

    def __init__(self, total: int, enabled: bool, label: str, *, unit: str = "step",
                 initial: int = 0, stream: TextIO | None = None, leave: bool = True) -> None:
        self.total, self.n, self.enabled, self.label, self.unit = total, initial, enabled, label, unit
        self.stream = sys.stderr if stream is None else stream
        self.bar, self.last, self.t0, self.width = None, 0.0, time.perf_counter(), 0
        if not enabled:
            return
        try:
            from tqdm import tqdm  # optional
            self.bar = tqdm(total=total, initial=initial, desc=label, unit=unit,
                            file=self.stream, dynamic_ncols=True, leave=leave)
        except ImportError:
            self._print("", force=True)

    def update(self, k: int = 1, note: str = "") -> None:
        """Advance by ``k`` steps; ``note`` (e.g. the item just done) is shown beside."""
        self.n += k
        if self.bar is not None:
            if note:
                self.bar.set_postfix_str(note[:40], refresh=False)
            self.bar.update(k)
        elif self.enabled:
            self._print(note)

    def _print(self, note: str, force: bool = False) -> None:
        now = time.perf_counter()
        if force or note or now - self.last > 0.5 or self.n == self.total:
            self.last = now
            line = (f"{self.label}: {self.n}/{self.total} {self.unit}s "
                    f"({now - self.t0:.0f} s) {note[:50]}").rstrip()
            self.width = max(self.width, len(line))
            self.stream.write(f"\r{line:<{self.width}}")
            self.stream.flush()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
        elif self.enabled:
            self.stream.write("\n")
            self.stream.flush()
