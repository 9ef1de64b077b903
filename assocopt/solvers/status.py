"""From a solver's own status to assocopt's: the one rule for "optimal, but to a gap".

Each back end maps its solver's native statuses with one table (a dict from the
native name to :class:`~assocopt.model.solution.Status`, looked up by :func:`from_table`);
:func:`settle_optimal` is the single place that turns an ``OPTIMAL`` claim into
``FEASIBLE`` when the solver was allowed to stop at a gap (``mip_gap > 0``) and the gap
it reached is not zero, or when its own bound contradicts the claim.
"""

from __future__ import annotations

from typing import Mapping

from ..problems.problem import OPT_TOL
from ..model.solution import Status

__all__ = ["GAP_ZERO", "from_table", "settle_optimal"]

#: A reached relative gap up to this counts as zero (floating-point round-off).
GAP_ZERO = OPT_TOL


def from_table(table: Mapping[str, Status], native: str) -> Status:
    """``table[native]``; a status the table does not know is an ``ERROR``."""
    return table.get(native, Status.ERROR)


def settle_optimal(status: Status, gap: float | None, mip_gap: float, *,
                   claim_tol: float | None = None) -> tuple[Status, str]:
    """``(status, note)`` with ``OPTIMAL`` kept only where it is proven.

    ``gap``: the relative gap the solver reached (None: it reports no bound);
    ``mip_gap``: the gap it was allowed to stop at (pass 0 for LPs).  With
    ``mip_gap > 0`` an ``OPTIMAL`` claim needs a reached gap of at most
    :data:`GAP_ZERO`; with ``mip_gap == 0`` and ``claim_tol`` given, a claim whose own
    bound is further than ``claim_tol`` from the objective is ``FEASIBLE`` too.
    """
    if status is not Status.OPTIMAL:
        return status, ""
    if mip_gap > 0:
        if gap is None:
            return Status.FEASIBLE, "mip_gap > 0 and the solver reports no bound"
        if gap > GAP_ZERO:
            return Status.FEASIBLE, f"stopped at relative gap {gap:.3g}"
    elif claim_tol is not None and gap is not None and gap > claim_tol:
        return Status.FEASIBLE, f"reached relative gap {gap:.3g}, not proven optimal"
    return Status.OPTIMAL, ""
