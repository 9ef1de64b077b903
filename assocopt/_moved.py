"""Old import paths of modules that moved: one helper the shim modules share.

A shim is a tiny module at the old path.  :func:`reexport` fills it with the new
module's public names (the very same objects, so ``isinstance`` checks and pickles
agree whichever path a caller used), forwards any other attribute (private names)
to the new module, and registers the new module's submodules under the old dotted
name (``assocopt.costs.sd_builder`` *is* ``assocopt.tracking.costs.sd_builder``).
The shim stays a module of its own, so tools that import files by path (pytest's
doctest collection) find the file they expect.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
from typing import Any, Callable

__all__ = ["reexport"]


def reexport(namespace: dict[str, Any], new: str,
             renamed: dict[str, str] | None = None) -> Callable[[str], Any]:
    """Fill the shim ``namespace`` (its ``globals()``) from module ``new``.

    ``renamed`` maps an old submodule name to its new one (``{"divergence": "kld"}``).
    Returns the module-level ``__getattr__`` that forwards other names.
    """
    mod = importlib.import_module(new)
    old = namespace["__name__"]
    names = list(getattr(mod, "__all__", [n for n in vars(mod) if not n.startswith("_")]))
    namespace.update({n: getattr(mod, n) for n in names})
    namespace["__all__"] = names
    subs = {info.name[len(new) + 1:]: info.name
            for info in pkgutil.walk_packages(getattr(mod, "__path__", []), new + ".")}
    subs.update({was: f"{new}.{now}" for was, now in (renamed or {}).items()})
    for short, full in subs.items():
        sub = importlib.import_module(full)
        sys.modules[f"{old}.{short}"] = sub
        if "." not in short:
            namespace[short] = sub

    def __getattr__(name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(mod, name)

    return __getattr__
