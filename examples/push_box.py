"""The robot dog pushes a box along the ground: bodies that touch.

The dog walks at its commanded speed; a 0.3 x 0.25 m box (2 kg, friction 0.3 with the ground)
stands just in front of it. The dog's torso box and leg capsules collide with the box (the
dog's own parts do not collide with each other, its feet are its contacts), so it shoves the
box ahead of it, against the box's sliding friction (about 5.9 N).

    python examples/push_box.py [--duration 12] [--gif docs/gifs/push_box.gif]
"""
import argparse

import walkers

BOX = dict(width=0.3, height=0.25, mass=2.0, mu=0.3)   # [m], [m], [kg], [-]


def add_box(builder, x=0.42):
    """The box to push, resting on flat ground with its left face at x - width / 2 [m]."""
    w, h, m = BOX["width"], BOX["height"], BOX["mass"]
    builder.add_body("box", m, m * (w * w + h * h) / 12, pos=(x, h / 2),
                     shapes=[("box", (0.0, 0.0), w, h, {"mu": BOX["mu"]})])


def main(duration=12.0, gif=None):
    """Run the push; returns (box travel [m], summary dict)."""
    traj, summary, model = walkers.load("quadruped").simulate(duration, gait="walk", extras=add_box)
    box = model.body("box")
    travel = float(traj.q[-1, box, 0] - model.q0[box, 0])
    if gif:
        from planarsim.render import export_animation
        export_animation(traj, model, gif, fps=10, speed=2.0, size=(3.6, 2.0), colors=32)
    return travel, summary


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=12.0)
    ap.add_argument("--gif", default=None, help="write an animation here")
    args = ap.parse_args()
    travel, summary = main(args.duration, args.gif)
    print(f"the dog walked {summary['distance']:.2f} m and pushed the box {travel:.2f} m "
          f"in {summary['time']:.1f} s; fell: {summary['fell']}; audit {summary['audit']}")
