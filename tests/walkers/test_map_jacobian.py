"""The passive walkers' step map with its exact Jacobian (walkers.passive.map_jacobian):
against centred differences of the map, against the polynomial fits' multipliers within their
error estimate, Newton with it, and its multipliers converging to the rimless wheel's closed
form at the map's order; the scipy reference's variational equations against differences of
the reference map."""
import numpy as np
import pytest

from planarsim.analysis import (StepMapError, find_fixed_point, match_distance, multipliers_by_fit,
                                multipliers_exact, sort_multipliers)
from planarsim.analysis.stepmap import jacobian
from walkers.passive import CompassParams, PassiveWalker, RimlessParams, SimplestParams
from walkers.passive.compass_gait import default_start
from walkers.passive.reference import (simplest_feet_map, simplest_feet_step_jacobian,
                                       simplest_fixed_point)
from walkers.passive.rimless_wheel import closed_form
from walkers.passive.simplest import garcia_start


def walker(kind, dt=1e-3):
    """(PassiveWalker, a start near its gait)."""
    if kind == "rimless":
        p = RimlessParams()
        return PassiveWalker(p, dt=dt), np.array([-closed_form(p)["omega_after"]])
    if kind == "simplest":
        return PassiveWalker(SimplestParams(), dt=dt), garcia_start()
    return PassiveWalker(CompassParams(), dt=dt), default_start()


@pytest.mark.parametrize("kind", ["rimless", "simplest", "compass"])
def test_the_exact_jacobian_matches_centred_differences(kind):
    """Off the gait (the start nudged), the map's exact Jacobian is within 1e-7 of centred
    differences of the map (step 1e-6, relative to its largest entry; measured 1e-9 to
    6e-9), the value it comes with is the map's, and the simulator's options are left as
    they were (their speed limit's origin too)."""
    w, x = walker(kind)
    x = x + 1e-3 * np.linspace(1.0, -1.0, x.size)
    f = w.step_map()
    options, from_model = w.sim.options, w.sim._speed_from_model
    y, J = f.value_and_jacobian(x)
    assert w.sim.options == options and w.sim._speed_from_model == from_model
    assert np.array_equal(y, f(x))
    D = jacobian(f, x, 1e-6)
    assert np.abs(J - D).max() <= 1e-7 * np.abs(D).max(), (J, D)


#: the exact Jacobian's rounding, a product of about a thousand steps' (the rimless wheel's
#: fit, whose estimate is 7e-13 there, sits 1.2e-12 from it)
ROUNDING = 1e-10


@pytest.mark.parametrize("kind", ["rimless", "simplest"])
def test_newton_and_the_multipliers_with_the_exact_jacobian(kind):
    """Newton takes the exact Jacobian (the default for a map that has one: every Jacobian it
    uses comes from the map's derivative) and reaches the gait in at most 5 iterations; the
    multipliers agree with multipliers_by_fit's within that fit's error estimate at dt 1e-3
    (for the simplest walker the fit's truncation error, 2.7e-6 at its default window, which
    its estimate measures to 0.3 %)."""
    w, x = walker(kind)
    f = w.step_map()
    calls = []
    derivative = f.derivative
    f.derivative = lambda z: calls.append(1) or derivative(z)
    fp = find_fixed_point(f, x, tol=1e-12)
    assert fp.converged and fp.iterations <= 5, (fp.iterations, fp.history)
    assert len(calls) == fp.iterations + 1          # each step's and the final Jacobian
    exact = multipliers_exact(f, fp.x)
    assert np.array_equal(exact.jacobian, fp.jacobian)
    fit = multipliers_by_fit(f, fp.x, warn=False)
    assert match_distance(exact.values, fit.values) <= fit.error + ROUNDING, (
        exact.values, fit.values, fit.error)


def test_the_rimless_wheels_multiplier_is_smooth_and_second_order():
    """The wheel's multiplier from the exact Jacobian: smooth as the touchdown moves through
    its sim step (six starts 2e-4 rad/s apart, more than a sim step's worth: the second
    differences of the multiplier within 1e-7, where the earlier sub-step to the touchdown
    swung it by 2.5e-3 across each sim step), and second order in dt against its closed form
    eta^2: the pivot, a contact held through the stance, aims its velocity at its gap at the
    free motion's end as a pin does, and the error falls fourfold per halving of dt within
    1 % (measured 8.2e-7 at dt 1e-3, 2.1e-7 at 5e-4; when the held contact's target was first
    order, 6.1e-4 and 3.0e-4)."""
    p = RimlessParams()
    eta2 = closed_form(p)["eta"] ** 2
    w, x = walker("rimless")
    f = w.step_map()
    lam = np.array([f.jacobian(x + 2e-4 * k)[0, 0] for k in range(6)])
    assert np.abs(np.diff(lam, 2)).max() <= 1e-7, lam
    errors = []
    for dt in (1e-3, 5e-4):
        w, x = walker("rimless", dt)
        f = w.step_map()
        fp = find_fixed_point(f, x, tol=1e-13, exact=False)
        errors.append(multipliers_exact(f, fp.x).values[0].real - eta2)
    assert 3.96 <= errors[0] / errors[1] <= 4.04, errors


def test_on_hills_the_map_has_no_exact_jacobian_and_newton_takes_differences():
    from planarsim import terrain
    p = SimplestParams()
    hills = terrain.hills([1e-4], [0.7], grade=-np.tan(p.slope))
    f = PassiveWalker(p, dt=1e-3, terrain=hills).step_map()
    assert not f.exact
    with pytest.raises(NotImplementedError, match="no exact Jacobian"):
        f.jacobian(garcia_start())
    fp = find_fixed_point(f, garcia_start(), tol=1e-9)
    assert fp.converged


def test_the_variational_reference_matches_differences_of_the_reference_map():
    """The scipy reference's Jacobian from its variational equations (with the event-time
    term at heel strike) against centred differences of the reference map at its gait."""
    p = SimplestParams()
    f = simplest_feet_map(p)
    x = find_fixed_point(f, simplest_fixed_point()["x"], tol=1e-12, eps=1e-7).x
    xn, J = simplest_feet_step_jacobian(x, p)
    assert np.abs(xn - x).max() <= 1e-11
    D = jacobian(f, x, 1e-6)
    assert np.abs(J - D).max() <= 1e-6 * np.abs(D).max()
    lam = sort_multipliers(np.linalg.eigvals(J))
    assert match_distance(lam, sort_multipliers(np.linalg.eigvals(D))) <= 1e-6


def test_a_map_without_an_exact_jacobian_says_so():
    from planarsim.analysis import StepMap
    f = StepMap(lambda x: 0.5 * x, dim=1)
    assert not f.exact
    with pytest.raises(NotImplementedError, match="no exact Jacobian"):
        f.jacobian(np.zeros(1))
    with pytest.raises(ValueError, match="exact=True"):
        find_fixed_point(f, np.ones(1), exact=True)
    fp = find_fixed_point(f, np.ones(1))             # differences
    assert fp.converged and abs(fp.jacobian[0, 0] - 0.5) < 1e-9


def test_a_fall_raises_as_the_map_does():
    w, x = walker("simplest")
    with pytest.raises(StepMapError):
        w.step_map().value_and_jacobian(np.array([0.6, 2.0, 1.2, 0.0]))
