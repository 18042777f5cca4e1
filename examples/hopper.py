"""A planar one-legged hopper with a Raibert-style controller, built from scratch.

Two point masses (hip 10 kg, foot 1 kg), a telescoping leg (an axial actuator acting as a
spring with thrust), and, in flight, forces that swing the foot to where Raibert's rule
places it: x_foot - x_hip = v T_stance / 2 + k_v (v - v_desired).

    python examples/hopper.py [--duration 10] [--speed 0.8] [--out hopper.gif]
"""
import argparse
import math

import numpy as np

import planarsim as ps

M_HIP, M_FOOT, L0 = 10.0, 1.0, 1.0           # kg, kg, m (leg rest length)
K_LEG = M_HIP * (math.pi / 0.18) ** 2        # N/m: a stance of about 0.18 s
T_STANCE = math.pi * math.sqrt(M_HIP / K_LEG)


def build():
    b = ps.ModelBuilder(dt=1e-3)
    hip = b.add_point_mass("hip", M_HIP, pos=(0.0, L0 + 0.1), radius=0.08)
    foot = b.add_point_mass("foot", M_FOOT, pos=(0.0, 0.1))
    b.add_point_contact("foot", foot, mu=1.0)
    b.add_axial("leg", hip, foot, limit=(-500.0, 3000.0))
    for axis, d in (("x", (1.0, 0.0)), ("y", (0.0, 1.0))):   # swing forces, foot and reaction
        b.add_body_force(f"swing_{axis}", foot, direction=d, limit=(-300.0, 300.0))
        b.add_body_force(f"swing_{axis}_reaction", hip, direction=d)
    return b.compile()


class Raibert:
    """Controller: sim -> commands [leg, swing_x, swing_x_reaction, swing_y, swing_y_reaction]."""

    def __init__(self, speed=0.8, hop_energy=20.0, k_v=0.15):
        self.speed, self.hop_energy, self.k_v = speed, hop_energy, k_v

    def __call__(self, sim):
        (xh, yh, _), (xf, yf, _) = sim.state.q
        (vxh, vyh, _), (vxf, vyf, _) = sim.state.v
        dx, dy = xf - xh, yf - yh
        length = math.hypot(dx, dy)
        rate = (dx * (vxf - vxh) + dy * (vyf - vyh)) / length
        spring = K_LEG * (L0 - length)
        u = np.zeros(5)
        if sim.state.contact_mode[0] != 0:                   # stance: spring + thrust
            energy = 0.5 * M_HIP * vyh ** 2 + M_HIP * 9.81 * yh
            thrust = 30.0 * max(0.0, self.hop_energy + M_HIP * 9.81 * L0 - energy)
            u[0] = spring + (thrust if rate > 0 else 0.0)
        else:                                                 # flight: place the foot
            x_target = vxh * T_STANCE / 2 + self.k_v * (vxh - self.speed)
            y_target = -math.sqrt(max(L0 ** 2 - x_target ** 2, 0.25))
            fx = 400.0 * (x_target - dx) - 40.0 * (vxf - vxh)
            fy = 400.0 * (y_target - dy) - 40.0 * (vyf - vyh)
            u[0] = 0.2 * spring
            u[1:] = fx, -fx, fy, -fy
        return u


def run(duration=10.0, speed=0.8):
    model = build()
    sim = ps.Simulator(model)
    traj = sim.run(duration, controller=Raibert(speed), record_every=10)
    hip = traj.q[:, 0, :2]
    half = traj.t > duration / 2
    summary = dict(distance=float(hip[-1, 0] - hip[0, 0]),
                   mean_speed=float(np.polyfit(traj.t[half], hip[half, 0], 1)[0]),
                   min_hip_height=float(hip[:, 1].min()),
                   hops=int(np.sum(np.diff((traj.contact_mode[:, 0] != 0).astype(int)) == 1)))
    return traj, summary, model


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=10.0)
    ap.add_argument("--speed", type=float, default=0.8)
    ap.add_argument("--out", default=None, help="animation file (.gif/.mp4)")
    a = ap.parse_args()
    traj, summary, model = run(a.duration, a.speed)
    print(summary)
    if a.out:
        from planarsim.render import export_animation
        export_animation(traj, model, a.out, fps=20)
