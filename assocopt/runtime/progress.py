"""One progress display for every long loop (experiment runs, ``assocopt compare``).

:class:`Progress` shows a tqdm bar on the stream (stderr by default) when enabled,
the label and the item just done beside the count, and writes nothing when disabled
(callers enable it when stderr is a terminal or when asked).
"""

from __future__ import annotations

import sys
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """Counter of ``total`` steps, starting at ``initial``; call :meth:`close` at the end.

    ``n`` counts the steps done even when disabled (no bar is made then, and tqdm is
    not imported).
    """

    def __init__(self, total: int, enabled: bool, label: str, *, unit: str = "step",
                 initial: int = 0, stream: TextIO | None = None, leave: bool = True) -> None:
        self.total, self.n, self.enabled = total, initial, enabled
        self.label, self.unit = label, unit
        self.bar = None
        if enabled:
            from tqdm import tqdm
            self.bar = tqdm(total=total, initial=initial, desc=label, unit=unit,
                            file=sys.stderr if stream is None else stream,
                            dynamic_ncols=True, leave=leave)

    def update(self, k: int = 1, note: str = "") -> None:
        """Advance by ``k`` steps; ``note`` (e.g. the item just done) is shown beside."""
        self.n += k
        if self.bar is not None:
            self.bar.update(k)
            if note:                       # shown at once, with the count it belongs to
                self.bar.set_postfix_str(note[:40])

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
