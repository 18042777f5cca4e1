"""The workspace's list of active rows: appending a row (its kind, owner and two bodies) and
moving one to an earlier slot (compacting the list in place). The kinds' modules append their
rows here; what a row means is theirs (codes.ROW_*, dispatched in rows.py)."""
from ...compile import kernel


@kernel
def add_row(ws, n, kind, owner, a, b):
    """Row slot n <- (kind, owner, bodies a and b); returns n + 1. Where slot n is beyond
    the workspace's storage, nothing is written, ws.room[0] is set (the step begins again
    with more: kernels/step.py, GUARD_ROOM) and n is returned."""
    if n >= ws.row_kind.shape[0]:
        ws.room[0] = 1
        return n
    ws.row_kind[n] = kind
    ws.row_owner[n] = owner
    ws.row_body[n, 0] = a
    ws.row_body[n, 1] = b
    return n + 1


@kernel
def move_row(ws, k, r):
    """Row r's kind, owner, bodies, error, Jacobian and impulse direction into slot k <= r
    (compacting the row list in place)."""
    ws.row_kind[k] = ws.row_kind[r]
    ws.row_owner[k] = ws.row_owner[r]
    ws.row_body[k, 0] = ws.row_body[r, 0]
    ws.row_body[k, 1] = ws.row_body[r, 1]
    ws.row_c[k] = ws.row_c[r]
    ws.row_c_pred[k] = ws.row_c_pred[r]
    ws.row_b[k] = ws.row_b[r]
    for c in range(ws.row_soft.shape[1]):
        ws.row_soft[k, c] = ws.row_soft[r, c]
    for e in range(2):
        for c in range(3):
            ws.row_J[k, e, c] = ws.row_J[r, e, c]
            ws.row_F[k, e, c] = ws.row_F[r, e, c]
