"""A rollout's recording: the frame and the controller's labels of the steps it records."""
from planarsim.compiled import jit, kernel, record_frame


@kernel
def record_labelled(s, ws, rec, lab, mem, slots, every, k):
    """On every `every`-th step, while the recorder has room: frame k of rec (make_recorder)
    and row k of lab (memory slots `slots` of mem). Returns the next frame index."""
    if s.step[0] % every == 0 and k < rec.t.shape[0]:
        record_frame(s, ws, rec, k)
        for c in range(slots.shape[0]):
            lab[k, c] = mem[slots[c]]
        return k + 1
    return k


@jit
def record_one(s, ws, rec, k):
    """Frame k of rec from State s and Workspace ws, from Python (record_frame is a kernel)."""
    record_frame(s, ws, rec, k)
