"""The last step's impulses as the start of the next step's solve, where it matters.

Where the rows of a step are independent the solve's answer does not depend on where it
starts (up to rounding): it starts from zero. Where they are not (a closed loop through the
ground: a box on two corners, two feet in double stance), the answer is a load split out of
many: the linear solve drops a dependent row, and the impulse that row keeps decides the
split. At zero, that split pulls or leaves friction outside its cone at rest, and every
resting step went to the complementarity solve. So where the factorisation dropped a row,
the solve starts from the last step's impulses (as the State records them: the velocity
solve's and the share of the position correction's that became velocity) and finds the
change from them: the dropped rows keep theirs, and a resting loop, whose change is then zero, keeps its split bit for bit.
The impulses live in the State (last_*_impulse), so a restored run continues bit for bit.
"""
from ...compile import kernel
from ..constraints.rows import (has_mode_rows, is_joint_row, is_limit_row, last_impulse,
                                store_joint_impulse)


@kernel
def start_impulses(s, ws, n, dropped):
    """ws.lam_start[:n]: each row's impulse in the last step, where the factorisation dropped
    a row as dependent (dropped > 0). Returns False (and starts nothing) when none was
    dropped, or no row is a contact or limit: joint rows alone have one answer, so where the
    solve starts cannot matter."""
    if dropped == 0:
        return False
    if not has_mode_rows(ws, n):
        return False
    for r in range(n):
        ws.lam_start[r] = last_impulse(s, ws, r)
    return True


@kernel
def remember_impulses(s, ws):
    """The step's impulses into the State (rows 0..n_row-1 with ws.lam; contacts from
    ws.contact_impulse, which holds the friction of sliding contacts too)."""
    for k in range(ws.n_live[0]):
        i = ws.live[k]
        s.last_contact_impulse[i, 0] = ws.contact_impulse[i, 0]
        s.last_contact_impulse[i, 1] = ws.contact_impulse[i, 1]
    for j in range(s.last_pin_impulse.shape[0]):
        for k in range(4):
            s.last_pin_impulse[j, k] = 0.0
    for j in range(s.last_rod_impulse.shape[0]):
        s.last_rod_impulse[j] = 0.0
    for r in range(ws.n_row[0]):
        if is_joint_row(ws.row_kind[r]) or is_limit_row(ws.row_kind[r]):
            store_joint_impulse(s, ws, r, ws.lam[r])
