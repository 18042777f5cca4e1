"""planarsim.checks: the argument checks the entry points share, and the places that call
them refusing alike (True and False are no numbers anywhere)."""
import math

import numpy as np
import pytest

from planarsim import ModelError, terrain
from planarsim.analysis.events import step_events
from planarsim.checks import MAX_STEPS, finite_number, number, pair, to_float, whole
from planarsim.render.frames import figure_size
from walkers.base import target_speed


@pytest.mark.parametrize("value, strict, expected", [
    (2, False, 2.0), (np.float64(0.5), True, 0.5), ("1.5", False, 1.5), ("1.5", True, None),
    (True, False, None), (np.True_, False, None), (None, False, None), ([1.0], False, None),
    ("abc", False, None), (10 ** 400, False, None),
])
def test_to_float(value, strict, expected):
    assert to_float(value, strict) == expected


@pytest.mark.parametrize("call, said", [
    (lambda: number("mass", "heavy"), r"^mass='heavy' must be a number$"),
    (lambda: number("mass", math.inf), r"^mass=inf must be finite$"),
    (lambda: finite_number("gain", np.nan, least=0.0), r"^gain=nan must be a finite number >= 0$"),
    (lambda: finite_number("v", 5.0, 0.0, 3.0, unit=" m/s"), r"^v=5.0 m/s must be a finite number within \[0, 3\]$"),
    (lambda: whole("period", 2.5, 1), r"^period=2.5 must be a whole number$"),
    (lambda: whole("period", 0, 1), r"^period=0 must be a whole number >= 1$"),
    (lambda: whole("n", MAX_STEPS + 1, 0, MAX_STEPS, why="steps in one call"),
     r"^n=1000000001 must be a whole number from 0 to 1,000,000,000 \(steps in one call\)$"),
    (lambda: pair("range", (2.0, 1.0), increasing=True), r"^range=\(2.0, 1.0\) must have low < high"),
    (lambda: pair("range", (1.0, 2.0, 3.0)), r"^range=\(1.0, 2.0, 3.0\) must be a pair \(low, high\)"),
])
def test_messages_name_the_argument_and_its_value(call, said):
    with pytest.raises(ValueError, match=said):
        call()


def test_whole_numbers_pass_as_ints():
    assert whole("n", 3.0, 0) == 3 and type(whole("n", np.int64(7), 0)) is int
    assert pair("range", [np.float64(-math.inf), 2]) == (-math.inf, 2.0)


@pytest.mark.parametrize("call, error, said", [
    (lambda: terrain.flat(True), ModelError, r"terrain: height=True must be a number"),
    (lambda: terrain.slope(False), ModelError, r"terrain: slope angle=False must be a number"),
    (lambda: figure_size((True, 3.6), 100), ValueError, r"size=\(True, 3.6\) must be \(width, height\)"),
    (lambda: figure_size((6.4, 3.6), True), ValueError, r"dpi=True must be a number"),
    (lambda: target_speed("walker", True), ValueError, r"walker: speed=True m/s must be a finite number"),
    (lambda: whole("period", True, 1), ValueError, r"period=True must be a whole number \(not True or False\)"),
])
def test_the_callers_take_no_bool_for_a_number(call, error, said):
    """flat(True) was ground 1 m up, a figure (True, 3.6) inches wide 1 inch, a speed of
    True 1 m/s and a period of True 1, all silently (float(True) is 1.0)."""
    with pytest.raises(error, match=said):
        call()


def test_step_events_settings_stay_strict():
    """(A string of digits is no number here, as before the checks were shared.)"""
    traj = type("T", (), dict(contact_mode=np.zeros((3, 1), int), contact_names=("a",),
                              t=np.arange(3) * 0.01))()
    with pytest.raises(ValueError, match=r"min_air='0.1' must be a finite number >= 0"):
        step_events(traj, feet=[["a"]], min_air="0.1")
