"""What a workspace's solve storage holds (planarsim/state.py sizes it; planarsim/errors.py
names it when a step runs out of room)."""
from __future__ import annotations


def workspace_contacts(model, ws) -> int:
    """Contacts the solve's storage of workspace ws holds (the inverse of state.max_rows)."""
    return (ws.row_kind.shape[0] - 5 * model.n_pin - model.n_rod) // 2


def workspace_capacity(model, ws) -> tuple[int, int, int]:
    """(contacts, envelope entries, island rows of the complementarity storage) that
    workspace ws's solve holds."""
    return workspace_contacts(model, ws), ws.A_low.shape[0], ws.lcp_A.shape[0]
