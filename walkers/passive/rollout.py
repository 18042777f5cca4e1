"""Compiled rollout of the passive walkers: the engine's step plus the foot bookkeeping that
the models need, with no Python call per step.

Foot bookkeeping (``update_feet``), after every step:
- with ``toggle`` (the simplest walker, the compass gait): the swing foot's contact stays
  disabled (it passes through the ground at mid-stance; scuffing is ignored in these models)
  until the foot is ahead of the stance foot along the ground tangent by more than
  min_ahead [m] AND above the ground (min_ahead > 0 keeps the scuff, where the swing foot
  passes the stance foot at ground level, from counting as a step);
- with DETECT (step-map evaluations) the non-stance feet stay disabled and a touchdown is a
  foot ahead of the stance foot that crosses the ground from above during a step;
- otherwise a touchdown is a non-stance foot whose contact went from free to pinned / sliding in this
  step; the touched foot becomes the stance foot and, with ``toggle``, the old stance foot's
  contact is disabled (it becomes the swing foot).
The old stance foot must leave the ground in the heel-strike step itself: that needs the
``all`` contact-mode strategy; with ``alternating`` the walker can lock.

memory (int64): [stance index into `feet`, touchdowns so far].
"""
import math

from planarsim.compiled import (RUN_FELL, RUN_NO_EVENT, closest_point, gap_of_point, jit,
                                record_frame, step)

MODE_FREE = 0
FELL = RUN_FELL          # return code: the watched body came closer to the ground than fall_height
NO_EVENT = RUN_NO_EVENT  # return code: n steps done without reaching stop_after touchdowns
ENGINE = 0         # toggle: every foot contact stays enabled; the engine finds the touchdowns
TOGGLE = 1         # toggle: swing contact disabled until past the stance foot and above ground
DETECT = 2         # toggle: non-stance contacts stay disabled; a touchdown is a non-stance foot
                   # ahead of the stance foot ending a step below the ground (the step map
                   # then locates the impact itself and lets the engine resolve it)


@jit
def contact_world(m, s, c):
    """World position [m] of contact c's material point (its local point on its body)."""
    b = m.contact_body[c]
    cs = math.cos(s.q[b, 2])
    sn = math.sin(s.q[b, 2])
    lx = m.contact_local[c, 0]
    ly = m.contact_local[c, 1]
    return s.q[b, 0] + cs * lx - sn * ly, s.q[b, 1] + sn * lx + cs * ly


@jit
def update_feet(m, s, ws, feet, memory, toggle, min_ahead):
    """Enable / detect / swap feet after one step (see module docstring); return the index
    (into feet) of the foot that touched down, or -1."""
    stance = feet[memory[0]]
    sx, sy = contact_world(m, s, stance)
    gx, gy, nx, ny, sgap = closest_point(m.terrain_coef, sx, sy)
    hit = -1
    for j in range(feet.shape[0]):
        if j == memory[0]:
            continue
        c = feet[j]
        if s.contact_enabled[c] == 0:
            if toggle:
                px, py = contact_world(m, s, c)
                ahead = (px - sx) * ny - (py - sy) * nx  # along the tangent (ny, -nx)
                gap = gap_of_point(m.terrain_coef, px, py)
                if toggle == DETECT and ahead > min_ahead and gap < 0.0 and hit < 0:
                    # only a crossing from above is a heel strike (a foot still below the
                    # ground after passing the stance foot is scuffing)
                    b = m.contact_body[c]
                    cs = math.cos(ws.prev.q[b, 2])
                    sn = math.sin(ws.prev.q[b, 2])
                    lx = m.contact_local[c, 0]
                    ly = m.contact_local[c, 1]
                    if gap_of_point(m.terrain_coef, ws.prev.q[b, 0] + cs * lx - sn * ly,
                                    ws.prev.q[b, 1] + sn * lx + cs * ly) >= 0.0:
                        hit = j
                elif toggle == TOGGLE and ahead > min_ahead and gap > 0.0:
                    s.contact_enabled[c] = 1
        elif hit < 0 and ws.prev.contact_mode[c] == MODE_FREE and s.contact_mode[c] != MODE_FREE:
            hit = j
    if hit >= 0:
        if toggle == TOGGLE:
            s.contact_enabled[stance] = 0
        memory[0] = hit
        memory[1] += 1
    return hit


@jit
def clock_step(s, dt):
    """The whole step nearest the state's clock, round(t / dt) with t = s.time [s] and dt the
    step size [s]: a frame's place on the recording schedule. It is the step count s.step of
    a run whose every step is dt long (an actuated walker's; a passive one's with the engine's
    touchdowns); a refined touchdown replaces the step it falls in by a sub-step and an
    impact step of 1e-6 s, two steps in s.step that move the clock by less than dt, so the
    count runs ahead of the clock by one a touchdown and a schedule by count would end short
    of the run's end."""
    return int(math.floor(s.time[0] / dt + 0.5))


@jit
def rollout_passive(m, s, ws, opt, u, feet, memory, toggle, min_ahead, n, stop_after,
                    fall_body, fall_height, rec, every, k0, event_time, event_contact):
    """Up to n steps; stop after `stop_after` touchdowns in total (memory[1]).

    Records a frame at every `every`-th whole step of the clock (clock_step; 0: none) and at
    each touchdown (not DETECT's) into rec from frame k0, and each touchdown's time [s] and
    contact id into event_time / event_contact (indexed by touchdown count).
    Returns (code, steps done, next frame): code 0 stop_after reached, NO_EVENT n steps done,
    FELL body fall_body within fall_height [m] of the ground, else the step's guard code.
    """
    k = k0
    for i in range(n):
        code = step(m, s, ws, opt, u)
        if code != 0:
            return code, i + 1, k
        hit = update_feet(m, s, ws, feet, memory, toggle, min_ahead)
        if hit >= 0:
            e = memory[1] - 1
            if e < event_time.shape[0]:
                event_time[e] = s.time[0]
                event_contact[e] = feet[hit]
        # touchdowns are recorded too (whole-step summaries start and end on them), except
        # DETECT's, which the step map still has to locate and resolve
        if every > 0 and (clock_step(s, m.dt) % every == 0 or (hit >= 0 and toggle != DETECT)) \
                and k < rec.t.shape[0]:
            record_frame(s, ws, rec, k)
            k += 1
        if hit >= 0 and memory[1] >= stop_after:
            return 0, i + 1, k
        if fall_body >= 0:
            if gap_of_point(m.terrain_coef, s.q[fall_body, 0], s.q[fall_body, 1]) < fall_height:
                return FELL, i + 1, k
    return NO_EVENT, n, k
