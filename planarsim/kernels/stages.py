"""The step's stages, written once: their numbers, names, modules and functions, in the order
step.step_of_length runs them. step.py's numbered comments, the kernel modules' docstrings
("Stage N: ...") and the documentation's table of the stages (stage_table) are checked
against this list (tests/planarsim/test_stages.py). Plain data: no numba here."""

#: (name, what it does, its modules (the first owns it), the functions that run it)
STAGES = (
    ("forces", "applied forces and the free velocity v* = v + h M^-1 f",
     ("forces", "fluid"), ("apply_forces", "apply_fluid", "predict_velocity")),
    ("contacts", "the contact points: ground queries, the broad phase, shape pairs",
     ("contacts", "broad_phase", "pair", "collide"),
     ("find_contacts", "find_contact", "find_edge", "update_live", "find_pair")),
    ("rows", "the active constraint rows J and their errors c, one module per kind",
     ("rows", "pin", "slider", "rod", "limit", "soft", "joint_friction", "joints"),
     ("build_rows", "eval_row", "pin_row", "slider_perp_row", "slider_angle_row", "rod_row",
      "limit_row", "soft_row", "friction_row", "ground_row", "pair_row")),
    ("impulses", "the rows' impulses: one linear solve",
     ("solve", "matrix", "envelope", "sparse_factor"), ("solve_impulses",)),
    ("modes", "the contacts' and limits' rules checked, then the guaranteed solve",
     ("modes", "complementarity", "islands", "mixed_lcp", "lcp"),
     ("rule_breaks", "seed_rule", "check_contact", "solve_contacts")),
    ("impact", "continuous collision: a step split at the time of impact",
     ("ccd", "pair_toi"), ("split_at_impact", "pair_impact_time", "hold_off_fast_pairs")),
    ("audit", "the step audits its own answer (of the impulses; of the positions at the end "
     "of stage 8)", ("audit", "work"), ("audit_impulses", "audit_joints")),
    ("positions", "integrate, correct, settle",
     ("position", "integrate"),
     ("position_stage", "integrate_positions", "correct_positions", "settle_positions",
      "bound_correction_work")),
    ("guards", "every coordinate finite and within its bound", ("guards",),
     ("check_guards", "check_speeds")),
)


def stage_number(name: str) -> int:
    """The number (from 1) of the stage called `name`."""
    for k, stage in enumerate(STAGES):
        if stage[0] == name:
            return k + 1
    raise KeyError(f"no stage {name!r}; the stages: {[s[0] for s in STAGES]}")


def stage_table() -> str:
    """The stages as a Markdown table (number and name, what it does, modules, functions)."""
    lines = ["| stage | what it does | modules (`planarsim/kernels/`) | functions |",
             "|---|---|---|---|"]
    for k, (name, what, modules, functions) in enumerate(STAGES):
        lines.append(f"| {k + 1}. {name} | {what} | "
                     + ", ".join(f"`{m}.py`" for m in modules) + " | "
                     + ", ".join(f"`{f}`" for f in functions) + " |")
    return "\n".join(lines)
