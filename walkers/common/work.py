"""The motors' work a walker's controller memory counts: each step once, from the engine's
power over the step (ws.act_power: the command times its coordinate's move, over dt)."""
from planarsim.compiled import kernel


@kernel
def once_per_step(s, mem, slot):
    """True the first time it is asked after each step of State s, so that a count made both
    after each step (a rollout) and at each control tick (the Python path) takes each step
    once; mem[slot] holds the State.step counted to (-1: a memory made for this state, whose
    steps before it are not its own)."""
    fresh = mem[slot] >= 0.0 and s.step[0] != mem[slot]
    mem[slot] = s.step[0]
    return fresh


@kernel
def add_positive_work(ws, mem, slot, dt):
    """Each actuator's positive work in the last step of dt [s] (ws.act_power times dt) into
    mem[slot] [J]."""
    for a in range(ws.act_power.shape[0]):
        if ws.act_power[a] > 0.0:
            mem[slot] += ws.act_power[a] * dt
