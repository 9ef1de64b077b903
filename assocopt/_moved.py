"""Old import paths of modules that moved: one helper the shim modules share.

:func:`alias` makes the old dotted name (and each of its submodules) refer to the
very module objects at the new place, so ``isinstance`` checks, monkeypatching and
pickles agree whichever path a caller used.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
from types import ModuleType

__all__ = ["alias"]


def alias(old: str, new: str, renamed: dict[str, str] | None = None) -> ModuleType:
    """Register module ``new`` (and its submodules) under the dotted name ``old``.

    ``renamed`` maps an old submodule name to its new one (``{"divergence": "kld"}``).
    """
    mod = importlib.import_module(new)
    sys.modules[old] = mod
    for info in pkgutil.walk_packages(getattr(mod, "__path__", []), new + "."):
        sys.modules[old + info.name[len(new):]] = importlib.import_module(info.name)
    for was, now in (renamed or {}).items():
        sys.modules[f"{old}.{was}"] = importlib.import_module(f"{new}.{now}")
    return mod
