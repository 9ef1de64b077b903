"""The one ``njit`` of assocopt: numba's, with the disk cache placed so that a kernel
never fails for want of a writable cache folder.

numba chooses a kernel's cache folder when the kernel is *decorated* (at import) and,
when it finds none it can write (a read-only install with a read-only home), raises
``RuntimeError: cannot cache function ...: no locator available`` at import time.  Every
compiled kernel of assocopt is decorated by :func:`njit` below instead, which decides,
once per process (per source folder for the in-tree test), where its cache goes:

1. ``NUMBA_CACHE_DIR`` when it is set and writable (numba's own rule);
2. numba's default, ``__pycache__`` next to the kernel's source file, when writable;
3. the user's cache, ``$XDG_CACHE_HOME/assocopt/numba`` (default
   ``~/.cache/assocopt/numba``), when writable;
4. a private temporary folder of this process (``tempfile.mkdtemp``, removed at exit):
   kernels compile once per process;
5. no disk cache at all.

Cases 3-5 are said once, as one line on the ``assocopt`` logger (``INFO`` for the user
cache, which persists; ``WARNING`` for 4 and 5, where every new process compiles
again).  The folder of cases 3 and 4 is handed to numba by setting
``numba.config.CACHE_DIR`` for the duration of the decoration only (numba reads it
then, to pick the locator, and never again for that kernel), so the user's own numba
functions keep numba's defaults.

Under ``NUMBA_DISABLE_JIT=1`` :func:`njit` returns the plain Python function, as
numba's does, and decides nothing.

May import: numba, the standard library (nothing of assocopt).
"""

from __future__ import annotations

import atexit
import functools
import logging
import os
import shutil
import tempfile
import threading
from typing import Any, Callable, NamedTuple

__all__ = ["njit", "cache_policy", "CachePolicy"]

_LOG = logging.getLogger("assocopt")
_LOCK = threading.Lock()


class CachePolicy(NamedTuple):
    """Where the kernels of this process are cached: ``kind`` is ``"numba"`` (numba's
    own choice: ``NUMBA_CACHE_DIR`` or next to the source), ``"user"``, ``"temporary"``
    or ``"none"``; ``folder`` the cache folder of ``"user"`` / ``"temporary"`` (else
    None); ``reason`` why, in words (empty for ``"numba"``)."""

    kind: str
    folder: str | None
    reason: str


#: This module loaded as part of the kernels' plain-Python twins (:mod:`.tiers`):
#: :func:`njit` returns each function unchanged and numba is never imported.
PLAIN = __name__.endswith("._plain.jit")


def njit(*args: Any, **options: Any) -> Any:
    """``numba.njit`` (same arguments: ``cache``, ``nogil``, ``inline``, a signature),
    with ``cache=True`` placed by the policy of this module; bare ``@njit`` works too."""
    if PLAIN:
        return args[0] if len(args) == 1 and callable(args[0]) and not options \
            else (lambda func: func)
    if len(args) == 1 and callable(args[0]) and not options:
        return _decorate(args[0], (), options)
    return lambda func: _decorate(func, args, options)


def _decorate(func: Callable, sigs: tuple, options: dict[str, Any]) -> Any:
    """Decorate ``func`` with numba, its cache folder chosen first."""
    import numba
    from numba.core import config

    if config.DISABLE_JIT or not options.get("cache"):
        return numba.njit(*sigs, **options)(func)
    source = os.path.dirname(os.path.abspath(func.__code__.co_filename))
    if _numba_can_cache(source):
        return numba.njit(*sigs, **options)(func)
    policy = _fallback()
    if policy.folder is None:
        return numba.njit(*sigs, **dict(options, cache=False))(func)
    with _LOCK:
        saved = config.CACHE_DIR
        config.CACHE_DIR = policy.folder
        try:
            return numba.njit(*sigs, **options)(func)
        finally:
            config.CACHE_DIR = saved


def _writable(folder: str) -> bool:
    """Whether ``folder`` can be created and written to (numba's own test)."""
    try:
        os.makedirs(folder, exist_ok=True)
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


@functools.lru_cache(maxsize=None)
def _numba_can_cache(source: str) -> bool:
    """Whether numba's own locators find a writable place for a kernel in ``source``:
    ``NUMBA_CACHE_DIR`` (as the process started) or ``source/__pycache__``."""
    from numba.core import config

    return bool(config.CACHE_DIR and _writable(config.CACHE_DIR)) or \
        _writable(os.path.join(source, "__pycache__"))


def _user_cache() -> str:
    """``$XDG_CACHE_HOME/assocopt/numba``, default ``~/.cache/assocopt/numba``."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"),
                                                            ".cache")
    return os.path.join(base, "assocopt", "numba")


def cache_policy() -> CachePolicy:
    """Where this process caches the kernels of this folder (``kind="numba"``: numba's
    own places); deciding a fallback says so, once a process (see the module doc)."""
    here = os.path.dirname(os.path.abspath(__file__))
    return CachePolicy("numba", None, "") if _numba_can_cache(here) else _fallback()


@functools.lru_cache(maxsize=1)
def _fallback() -> CachePolicy:
    """The fallback cache of this process, decided (and said, one log line) on the
    first kernel numba could not cache in its own places."""
    from numba.core import config

    here = os.path.dirname(os.path.abspath(__file__))
    where = f"NUMBA_CACHE_DIR={config.CACHE_DIR!r} and " if config.CACHE_DIR else ""
    why = f"{where}the package folder {here} are not writable"
    user = _user_cache()
    if _writable(user):
        policy = CachePolicy("user", user, why)
        _LOG.info("assocopt: %s; numba kernels are cached in %s", why, user)
        return policy
    why = f"{why}, nor is {user}"
    try:
        temp = tempfile.mkdtemp(prefix="assocopt-numba-")
    except OSError:
        temp = None
    if temp is not None and _writable(temp):
        atexit.register(shutil.rmtree, temp, ignore_errors=True)
        _LOG.warning("assocopt: %s; numba kernels are cached in %s for this process only "
                     "(compiled again in every new process; set NUMBA_CACHE_DIR to a "
                     "writable folder to keep them)", why, temp)
        return CachePolicy("temporary", temp, why)
    why = f"{why}, nor is a temporary folder"
    _LOG.warning("assocopt: %s; numba kernels are not cached (compiled again in every "
                 "new process; set NUMBA_CACHE_DIR to a writable folder)", why)
    return CachePolicy("none", None, why)
