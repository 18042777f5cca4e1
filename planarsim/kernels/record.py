"""Recording one frame of a run into preallocated arrays (a Recorder NamedTuple)."""
from ..compile import kernel


@kernel
def record_frame(s, ws, rec, k):
    """Write the state after a step into frame k of rec (see planarsim/trajectory.py); the
    actuators' work since the last frame starts again (ws.act_work)."""
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
    # a frame's power is the mean over the steps since the frame before (the work they did
    # over their time): the power times the time between frames is the work, however
    # sparse the frames
    span = ws.act_work_time[0]
    for a in range(ws.act_u.shape[0]):
        rec.act_u[k, a] = ws.act_u[a]
        rec.act_power[k, a] = ws.act_work[a] / span if span > 0.0 else ws.act_power[a]
        ws.act_work[a] = 0.0
    ws.act_work_time[0] = 0.0
