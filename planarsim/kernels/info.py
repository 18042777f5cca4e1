"""Slots of ws.info: what the last step did (counts reset at its start) and what its guard
found. Read them by name from Python with step_info(ws)."""
INFO_SOLVES = 0            # linear solves of the velocity stage (guess, retry)
INFO_CCD_SPLITS = 1        # time-of-impact splits of the step
INFO_GUARD_BODY = 2        # the guard's body (GUARD_NONFINITE, GUARD_TOO_LARGE)
INFO_GUARD_FIELD = 3       # the guard's field 0..5 of that body: x y theta vx vy omega
INFO_LCP_SOLVES = 4        # complementarity (Lemke) solves of the velocity stage
INFO_NEWTON_TAKEN_BACK = 5  # passes of the position correction taken back (a Newton step
                            # that diverged, a chord step that did not halve the error)
INFO_LCP_PIVOTS = 6        # Lemke pivots, velocity stage and projections
INFO_PROJECTIONS = 7       # complementarity projections of the positions
INFO_COMMAND = 8           # the command the guard names: index of a NaN / inf one
                           # (GUARD_NONFINITE_COMMAND), or how many were given (GUARD_BAD_COMMANDS)
INFO_CCD_STOPS = 9         # a step that used up its splits was cut at a fast pair's time of
                           # impact or turn horizon (ccd.stop_at_impact: the rest of its time
                           # dropped)
INFO_TURN_SUBSTEPS = 10    # sub-steps the step was taken in (1: whole; step.turn_substeps: a
                           # joint's anchor or a touching contact's point turning too far)
INFO_CHAIN_PATH = 11       # 1: the step was taken by the pin-chain path (step.chain_step), 0:
                           # by the general stages
INFO_KEPT_FACTORS = 12     # velocity solves on the factors kept from an earlier step's
                           # (solve.refine_on_kept_factors: a pile at rest)
INFO_SHAKE_WHOLE = 13     # position corrections kept whole as SHAKE's, within its regime
                           # (integrate.bound_correction_work: RATTLE, or joints alone)
INFO_SWITCH_ROUNDS = 14    # rounds of the mode switching (step.switch_rounds) the velocity
                           # stage took
# the rules the guess broke: the first answer of the velocity stage, under the modes the
# last step left (step.solve_modes; summed over a step's parts), counted by rule
# (modes.rule_breaks): why a step needed more than one solve, or the complementarity solve;
# in the order of codes.BROKE_* (slot INFO_GUESS_EQUATIONS + BROKE_*)
INFO_GUESS_EQUATIONS = 15   # rows whose equation the answer misses (a dependent row dropped
                            # whose target the others do not meet)
INFO_GUESS_PULLS = 16       # contact normals that pull
INFO_GUESS_REVERSALS = 17   # sliding contacts whose slip reversed
INFO_GUESS_CONES = 18       # pinned contacts' friction outside the cone
INFO_GUESS_LIMITS = 19      # joint limits that pull
N_INFO = 20

INFO_NAMES = ("solves", "ccd_splits", "guard_body", "guard_field", "lcp_solves",
              "newton_taken_back", "lcp_pivots", "projections", "command", "ccd_stops",
              "turn_substeps", "chain_path", "kept_factors", "shake_whole",
              "switch_rounds", "guess_equations", "guess_pulls", "guess_reversals",
              "guess_cones", "guess_limits")
# counted afresh by every step (the guard slots keep the last failure)
STEP_COUNTS = (INFO_SOLVES, INFO_CCD_SPLITS, INFO_LCP_SOLVES, INFO_NEWTON_TAKEN_BACK,
               INFO_LCP_PIVOTS, INFO_PROJECTIONS, INFO_CCD_STOPS, INFO_KEPT_FACTORS,
               INFO_SHAKE_WHOLE, INFO_SWITCH_ROUNDS, INFO_GUESS_EQUATIONS, INFO_GUESS_PULLS,
               INFO_GUESS_REVERSALS, INFO_GUESS_CONES, INFO_GUESS_LIMITS)


def step_info(ws) -> dict:
    """{name: value} of ws.info (Python side)."""
    return {name: int(ws.info[k]) for k, name in enumerate(INFO_NAMES)}
