"""Gait analysis: step events, Poincare sections, step-to-step maps, fixed points, Floquet
multipliers with error estimates, continuation of gaits in a parameter with bifurcation
detection, brute-force bifurcation diagrams, basins of attraction, step-level summaries,
and their plots.

Modules: events (touchdowns, sections), stepmap (StepMap, Jacobians, fixed points,
multipliers), parallel (MapPool: map evaluations on every core), continuation, bifurcation,
basin, summary (whole-step cost of transport, step length, speed), sensitivity (the gait
sensitivity norm), plots.
"""
from .events import IN_CONTACT, StepEvents, foot_groups, poincare_section, step_events, touchdowns
from .stepmap import (EPS_LADDER, FixedPoint, MultiplierWarning, Multipliers, StepMap, StepMapError,
                      central_jacobian, central_points, find_fixed_point, floquet_multipliers,
                      jacobian, map_noise, match_distance, multipliers_by_fit,
                      multipliers_exact, multipliers_with_error, serial_evaluator, sort_multipliers)
from .bifurcation import Basin, Diagram, basin_of_attraction, bifurcation_diagram
from .continuation import (Bifurcation, Branch, BranchPoint, continue_branch, newton_fixed_point,
                           period_doubling_branch, bifurcation_tests, write_csv)
from .parallel import MapPool, compose
from .sensitivity import GaitSensitivity, gait_sensitivity, gait_sensitivity_norm
from .summary import frame_from_state, step_summary
from .plots import (plot_basin, plot_bifurcation_diagram, plot_branch_multipliers, plot_limit_cycle,
                    plot_multipliers)

__all__ = [
    "IN_CONTACT", "StepEvents", "foot_groups", "poincare_section", "step_events", "touchdowns",
    "EPS_LADDER", "FixedPoint", "MultiplierWarning", "Multipliers", "StepMap", "StepMapError",
    "central_jacobian", "central_points", "find_fixed_point", "floquet_multipliers", "jacobian",
    "map_noise", "match_distance", "multipliers_by_fit", "multipliers_exact",
    "multipliers_with_error",
    "serial_evaluator", "sort_multipliers",
    "Bifurcation", "Branch", "BranchPoint", "continue_branch", "newton_fixed_point",
    "period_doubling_branch", "bifurcation_tests", "write_csv", "MapPool", "compose",
    "GaitSensitivity", "gait_sensitivity", "gait_sensitivity_norm",
    "frame_from_state", "step_summary", "Basin", "Diagram", "basin_of_attraction",
    "bifurcation_diagram", "plot_basin", "plot_bifurcation_diagram", "plot_branch_multipliers", "plot_limit_cycle", "plot_multipliers",
]
