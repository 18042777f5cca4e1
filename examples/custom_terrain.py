"""Walking on a terrain of your own: a sum of sines with a gentle uphill grade.

Any profile h(x) = h0 + s x + sum_k A_k sin(2 pi x / L_k + phi_k) is exact in the engine
(height, slope, normal, closest point). Here: two long swells and a ripple on a 2 % grade.

    python examples/custom_terrain.py [--duration 30]
"""
import argparse


import planarsim as ps
import walkers

TERRAIN = ps.terrain.hills(amplitudes=[0.15, 0.05, 0.01], wavelengths=[9.0, 4.1, 1.3],
                           phases=[0.0, 1.0, 2.0], grade=0.02)


def main(duration=30.0):
    print(f"largest slope {ps.terrain.max_slope_deg(TERRAIN):.1f} deg")
    traj, summary, model = walkers.load("simple-biped").simulate(duration, gait="walk", terrain=TERRAIN)
    hip = traj.q[:, 0, :2]
    climb = float(TERRAIN.height(hip[-1, 0]) - TERRAIN.height(hip[0, 0]))
    return summary, climb


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=30.0)
    summary, climb = main(ap.parse_args().duration)
    print(f"walked {summary['distance']:.1f} m, climbed {climb:.2f} m, fell: {summary['fell']}")
