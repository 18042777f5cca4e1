"""Plots (planarsim/render/plots.py): joint rates, cost of transport, summary figures."""

import numpy as np
import pytest

import planarsim as ps
from planarsim.render import cost_of_transport, joint_series, plot_summary, save_figure
from tests.render.helpers import box_model, pendulum_model, default_file_mode


def test_joint_rates_are_the_derivative_of_the_angles():
    model = pendulum_model(motor=False)
    traj = ps.Simulator(model).run(1.0, record_every=1)
    (ang, rate), = joint_series(traj, model).values()
    fd = np.gradient(ang, traj.t)
    np.testing.assert_allclose(rate[5:-5], fd[5:-5], atol=0.02 * np.abs(rate).max())
    assert np.ptp(ang) > 1.0   # it swung

    # a point-mass leg (axial actuator): segment angle from the vertical and its rate
    b = ps.ModelBuilder(gravity=(0.0, 0.0))
    hip = b.add_point_mass("hip", 1.0, pos=(0.0, 1.0), vel=(1.0, 0.0))
    foot = b.add_point_mass("foot", 1.0, pos=(0.0, 0.0))
    b.add_axial("leg", hip, foot)
    m2 = b.compile()
    tr2 = ps.Simulator(m2).run(0.5, record_every=1)
    (ang, rate), = joint_series(tr2, m2).values()
    # hip moving right over a resting foot: the leg hip->foot turns from straight down to behind
    d = tr2.q[:, 1, :2] - tr2.q[:, 0, :2]
    np.testing.assert_allclose(ang, np.arctan2(d[:, 0], -d[:, 1]), atol=1e-12)
    assert ang[-1] < -0.3
    np.testing.assert_allclose(rate[2:-2], np.gradient(ang, tr2.t)[2:-2], rtol=1e-3, atol=1e-6)


def test_cost_of_transport_of_a_box_dragged_at_constant_speed_is_mu():
    """Pushing a sliding box with F = mu m g keeps its speed; P = F v, so CoT = mu."""
    mu = 0.4
    model = box_model(pos=(0.0, 0.1), vel=(1.0, 0.0), mu=mu, push=True)
    sim = ps.Simulator(model)
    force = mu * model.total_mass * 9.81
    sim.run(0.3, u=np.array([force]))                      # settle the contact modes
    traj = sim.run(2.0, u=np.array([force]), record_every=5)
    speed = traj.com_velocity(model)[:, 0]
    assert np.ptp(speed) < 0.02 and speed.mean() > 0.5   # really dragged at constant speed
    inst, avg = cost_of_transport(traj, model)
    assert avg == pytest.approx(mu, rel=0.01)
    assert np.nanmedian(inst) == pytest.approx(mu, rel=0.01)


def test_summary_plots_save_by_extension(sliding_run, tmp_path):
    model, traj = sliding_run
    fig = plot_summary(traj, model)
    for ext, magic in (("png", b"\x89PNG"), ("svg", b"<?xml"), ("pdf", b"%PDF")):
        out = save_figure(fig, tmp_path / f"summary.{ext}")
        assert out.read_bytes()[:len(magic)] == magic
        assert out.stat().st_mode & 0o777 == default_file_mode()   # not mkstemp's owner-only mode
    # the energy panel plots the trajectory's own energies
    energy_ax = next(a for a in fig.axes if a.get_title() == "mechanical energy")
    total = next(l for l in energy_ax.get_lines() if l.get_label() == "total")
    np.testing.assert_allclose(total.get_ydata(), traj.energy(model)["total"])
    # the contact timeline covers exactly the frames in contact
    modes_ax = next(a for a in fig.axes if a.get_title() == "contact modes")
    dt_frame = traj.t[1] - traj.t[0]
    covered = sum(p.get_extents().width for coll in modes_ax.collections for p in coll.get_paths())
    assert covered == pytest.approx(dt_frame * np.count_nonzero(traj.contact_mode != 0), rel=1e-6)


def test_figure_with_unknown_extension_is_refused(sliding_run, tmp_path):
    model, traj = sliding_run
    with pytest.raises(ValueError, match=r"'\.jpeg' unknown.*\.png"):
        plot_summary(traj, model, tmp_path / "x.jpeg")
    fig = plot_summary(traj, model)
    with pytest.raises(ValueError, match="unknown"):
        save_figure(fig, tmp_path / "x")
    assert list(tmp_path.iterdir()) == []


def test_summary_plot_has_title_position_and_speed(sliding_run):
    import dataclasses
    model, traj = sliding_run
    traj = dataclasses.replace(traj, info={**traj.info, "walker": "box"})
    fig = plot_summary(traj, model)
    assert fig._suptitle.get_text() == "box on flat terrain"
    speed_ax = next(a for a in fig.axes if a.get_title() == "centre of mass: forward speed")
    line = speed_ax.get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), traj.com_velocity(model)[:, 0])
    pos_ax = next(a for a in fig.axes if a.get_title() == "centre of mass: position")
    dist = pos_ax.get_lines()[0].get_ydata()
    # slid from 1.5 m/s to rest at mu g: v^2 / (2 mu g) = 0.38 m from its start (frame 0)
    assert dist[0] == 0.0 and dist[-1] == pytest.approx(1.5 ** 2 / (2 * 0.3 * 9.81), abs=2e-3)
    assert "slope:3" in plot_summary(traj, model, title="box on slope:3 terrain")._suptitle.get_text()
