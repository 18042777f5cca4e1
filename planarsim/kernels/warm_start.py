"""The last step's impulses as the start of the next step's solve.

Where the rows of a step are independent the solve's answer does not depend on where it
starts (up to rounding). Where they are not (a closed loop through the ground: a box on two
corners, two feet in double stance), the answer is a load split out of many, and the linear
solve of the guess leaves a dependent row at its starting impulse. Starting from zero, that
split pulls or leaves friction outside its cone at rest, and every resting step went to the
complementarity solve; starting from the last step's answer, a resting loop keeps its split.
The impulses live in the State (last_*_impulse), so a restored run continues bit for bit.
"""
from ._jit import kernel
from .rows import (ROW_CONTACT_N, ROW_CONTACT_T, ROW_LIMIT_HI, ROW_LIMIT_LO, ROW_PIN_X,
                   ROW_PIN_Y, ROW_ROD)


@kernel
def start_impulses(s, ws, n):
    """ws.lam_start[:n]: each row's impulse in the last step (0 where it had none). A sliding
    contact's single row (impulse lambda_n along n - mu s t) starts at lambda_n. Returns
    False (and starts nothing) when no row is a contact or limit: joint rows alone have one
    answer, so where the solve starts cannot matter."""
    unilateral = False
    for r in range(n):
        if ws.row_kind[r] >= ROW_LIMIT_LO:
            unilateral = True
            break
    if not unilateral:
        return False
    for r in range(n):
        o = ws.row_owner[r]
        kind = ws.row_kind[r]
        x = 0.0
        if kind == ROW_CONTACT_N:
            x = s.last_contact_impulse[o, 0]
        elif kind == ROW_CONTACT_T:
            x = s.last_contact_impulse[o, 1]
        elif kind == ROW_PIN_X or kind == ROW_PIN_Y:
            x = s.last_pin_impulse[o, kind - ROW_PIN_X]
        elif kind == ROW_LIMIT_LO or kind == ROW_LIMIT_HI:
            x = s.last_pin_impulse[o, 2 + kind - ROW_LIMIT_LO]
        elif kind == ROW_ROD:
            x = s.last_rod_impulse[o]
        ws.lam_start[r] = x
    return True


@kernel
def remember_impulses(s, ws):
    """The step's impulses into the State (rows 0..n_row-1 with ws.lam; contacts from
    ws.contact_impulse, which holds the friction of sliding contacts too)."""
    for i in range(s.last_contact_impulse.shape[0]):
        s.last_contact_impulse[i, 0] = ws.contact_impulse[i, 0]
        s.last_contact_impulse[i, 1] = ws.contact_impulse[i, 1]
    for j in range(s.last_pin_impulse.shape[0]):
        for k in range(4):
            s.last_pin_impulse[j, k] = 0.0
    for j in range(s.last_rod_impulse.shape[0]):
        s.last_rod_impulse[j] = 0.0
    for r in range(ws.n_row[0]):
        o = ws.row_owner[r]
        kind = ws.row_kind[r]
        if kind == ROW_PIN_X or kind == ROW_PIN_Y:
            s.last_pin_impulse[o, kind - ROW_PIN_X] = ws.lam[r]
        elif kind == ROW_LIMIT_LO or kind == ROW_LIMIT_HI:
            s.last_pin_impulse[o, 2 + kind - ROW_LIMIT_LO] = ws.lam[r]
        elif kind == ROW_ROD:
            s.last_rod_impulse[o] = ws.lam[r]
