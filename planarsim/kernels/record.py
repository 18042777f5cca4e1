"""Recording one frame of a run into preallocated arrays (a Recorder NamedTuple)."""
from ..compile import kernel


@kernel
def record_frame(s, ws, rec, k):
    """Write the state after a step into frame k of rec (see planarsim/trajectory.py)."""
    rec.t[k] = s.time[0]
    for i in range(s.q.shape[0]):
        for c in range(3):
            rec.q[k, i, c] = s.q[i, c]
            rec.v[k, i, c] = s.v[i, c]
    for i in range(s.contact_mode.shape[0]):
        rec.contact_mode[k, i] = s.contact_mode[i] if s.contact_enabled[i] else -1
        for c in range(2):
            rec.contact_impulse[k, i, c] = ws.contact_impulse[i, c]
            rec.contact_point[k, i, c] = ws.contact_point[i, c]
            rec.contact_normal[k, i, c] = ws.contact_normal[i, c]
    for a in range(ws.act_u.shape[0]):
        rec.act_u[k, a] = ws.act_u[a]
        rec.act_power[k, a] = ws.act_power[a]
