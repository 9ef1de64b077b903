"""Paper 001's correct-association rates, with tracks that have no true partner.

The paper's "correct association probability" is not defined; it is measured on the
targets of the common observation area.  With partial coverage some tracks have no
partner on the other node, so we report two rates (both ours):

``common``  over the node-1 tracks whose emitter node 2 also sees: the decided partner
            is the true one (no partner counts as wrong).  With full coverage this is
            the rate of the earlier pages.
``all``     over every track of both nodes: a node-1 track is correct when its decided
            partner is its true one, or when it has none and is left unassociated; a
            node-2 track when exactly its true node-1 partner took it, or, having none,
            when no node-1 track took it (so a node-2 track given to two node-1 tracks
            by the maximum-degree rule is wrong).

>>> import numpy as np
>>> truth = np.array([1, 0, -1])          # node-1 track 2 has no partner; node 2 has 3 tracks
>>> rates(np.array([1, 0, -1]), truth, 3)
(1.0, 1.0)
>>> rates(np.array([1, 0, 2]), truth, 3)  # track 2 takes node-2 track 2, which has no partner
(1.0, 0.6666666666666666)
"""

from __future__ import annotations

import numpy as np

__all__ = ["rates"]


def rates(decided: np.ndarray, truth: np.ndarray, n2: int) -> tuple[float, float]:
    """``(common, all)`` rates of one scan (module docstring).

    ``decided`` and ``truth``: node-2 partner of each node-1 track, ``-1`` for none;
    ``n2``: the number of node-2 tracks.  An empty set of tracks scores 1.
    """
    decided = np.asarray(decided)
    truth = np.asarray(truth)
    if decided.shape != truth.shape:
        raise ValueError(f"decided and truth must have one shape, got {decided.shape}, "
                         f"{truth.shape}")
    if np.any(decided >= n2) or np.any(truth >= n2):
        raise ValueError(f"partners must be -1 or below n2 = {n2}")
    common = truth >= 0
    c = float(np.mean(decided[common] == truth[common])) if common.any() else 1.0
    row_ok = decided == truth
    takers = np.bincount(decided[decided >= 0], minlength=n2)
    owner = np.full(n2, -1)
    owner[truth[common]] = np.flatnonzero(common)
    owners_choice = decided[np.maximum(owner, 0)] if len(decided) else np.full(n2, -1)
    col_ok = np.where(owner >= 0, (takers == 1) & (owners_choice == np.arange(n2)),
                      takers == 0)
    total = len(decided) + n2
    a = float((row_ok.sum() + col_ok.sum()) / total) if total else 1.0
    return c, a
