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
    """Off the gait (the start nudged), the map's exact Jacobian is within 1e-6 of centred
    differences of the map (step 1e-6, relative to its largest entry), and the value it comes
    with is the map's."""
    w, x = walker(kind)
    x = x + 1e-3 * np.linspace(1.0, -1.0, x.size)
    f = w.step_map()
    y, J = f.value_and_jacobian(x)
    assert np.abs(y - f(x)).max() <= 1e-12
    D = jacobian(f, x, 1e-6)
    assert np.abs(J - D).max() <= 1e-6 * np.abs(D).max(), (J, D)


#: the fits' floor below their truncation error estimate: fits over windows of 2.5e-4 to
#: 1e-3 (estimates 3e-9 to 4e-8) sit 2e-8 to 3e-8 from the exact multipliers of the simplest
#: walker at dt 1e-3 (they average the map's slope over its pieces, the exact Jacobian is the
#: slope of the piece at x: a cubic fit over +-1e-4 around x matches it to 5e-9)
FIT_FLOOR = 1e-7


@pytest.mark.parametrize("kind", ["rimless", "simplest"])
def test_newton_and_the_multipliers_with_the_exact_jacobian(kind):
    """Newton with the exact Jacobian (the default for a map that has one) reaches the gait in
    at most 5 iterations; its multipliers agree with multipliers_by_fit's within that fit's
    error estimate (its truncation error, which at the default window is 2.7e-6 for the
    simplest walker) and its floor, at dt 1e-3."""
    w, x = walker(kind)
    f = w.step_map()
    fp = find_fixed_point(f, x, tol=1e-12)
    assert fp.converged and fp.iterations <= 5, (fp.iterations, fp.history)
    exact = multipliers_exact(f, fp.x)
    assert np.allclose(exact.jacobian, fp.jacobian, rtol=0, atol=1e-12)
    fit = multipliers_by_fit(f, fp.x, warn=False)
    assert match_distance(exact.values, fit.values) <= fit.error + FIT_FLOOR, (
        exact.values, fit.values, fit.error)


def test_the_rimless_wheels_multiplier_converges_at_first_order():
    """The wheel's multiplier from the exact Jacobian against its closed form eta^2: the
    map is first order in dt (its pivot is a contact, whose correction moves positions only),
    and so is the multiplier, cleanly: the error halves with dt (within 1 %), with no
    sawtooth of the touchdown's phase in it."""
    p = RimlessParams()
    eta2 = closed_form(p)["eta"] ** 2
    errors = []
    for dt in (1e-3, 5e-4):
        w, x = walker("rimless", dt)
        f = w.step_map()
        fp = find_fixed_point(f, x, tol=1e-13, exact=False)
        errors.append(multipliers_exact(f, fp.x).values[0].real - eta2)
    assert 1.98 <= errors[0] / errors[1] <= 2.02, errors


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
