"""Learn to swim: a linear policy for planarsim/Swimmer-v0 found by augmented random search.

Augmented random search (Mania, Guy and Recht 2018, "Simple random search provides a
competitive approach to reinforcement learning", its V1-t): the policy is a matrix M, action =
clip(M obs, -1, 1). Each iteration draws `directions` random matrices delta, runs the
policies M + nu delta and M - nu delta for one episode each (a pair starts from the same
seeded state), and steps M along the `top` best pairs' return differences:
    M += alpha / (top * sigma_R) * sum_k (R+_k - R-_k) delta_k
(sigma_R: the standard deviation of those returns). All 2 * directions episodes of an
iteration run at once on a PlanarVectorEnv (every core). The result is evaluated without
noise on `eval_episodes` fresh seeds.

    python examples/learn_swimmer.py [--iterations 40] [--gif docs/gifs/swimmer.gif]
"""
import argparse
import sys
import time

try:
    import gymnasium
except ImportError:     # (a plain install has no gymnasium: say what to install, not a traceback)
    sys.exit(f"{__file__}: needs gymnasium: pip install -e '.[gym]'")

import numpy as np

import planarsim.envs  # noqa: F401  (registers planarsim/Swimmer-v0)
from planarsim.envs.vector import PlanarVectorEnv

ENV = "planarsim/Swimmer-v0"


def episode_returns(envs, policies, seeds, horizon):
    """Return of one episode per copy (at most `horizon` steps), copy k acting with
    policies[k] (nu, n_obs) from reset seed seeds[k]."""
    obs, _ = envs.reset(seed=list(seeds))
    total = np.zeros(envs.num_envs)
    alive = np.ones(envs.num_envs, dtype=bool)
    for _ in range(horizon):
        actions = np.clip(np.einsum("kij,kj->ki", policies, obs), -1.0, 1.0)
        obs, reward, terminated, truncated, _ = envs.step(actions)
        total += np.where(alive, reward, 0.0)
        alive &= ~(terminated | truncated)
        if not alive.any():
            break
    return total


def learn(iterations=40, directions=8, top=4, alpha=0.02, nu=0.02, horizon=1000, seed=0,
          workers=None, eval_episodes=4, progress=True):
    """Augmented random search; returns dict(policy (nu, n_obs), history [(iteration, mean
    return of the iteration's episodes, seconds)], eval_return (mean of eval_episodes),
    seconds (learning, evaluation excluded))."""
    envs = PlanarVectorEnv(ENV, 2 * directions, workers=workers)
    try:
        n_act = envs.single_action_space.shape[0]
        n_obs = envs.single_observation_space.shape[0]
        rng = np.random.default_rng(seed)
        M = np.zeros((n_act, n_obs))
        history = []
        t0 = time.perf_counter()
        for it in range(iterations):
            delta = rng.standard_normal((directions, n_act, n_obs))
            policies = np.concatenate([M + nu * delta, M - nu * delta])
            start = rng.integers(0, 2 ** 31, size=directions)
            returns = episode_returns(envs, policies, np.concatenate([start, start]), horizon)
            r_plus, r_minus = returns[:directions], returns[directions:]
            best = np.argsort(-np.maximum(r_plus, r_minus))[:top]
            sigma = np.concatenate([r_plus[best], r_minus[best]]).std()
            step = ((r_plus[best] - r_minus[best])[:, None, None] * delta[best]).sum(0)
            M = M + alpha / (top * (sigma if sigma > 1e-12 else 1.0)) * step
            history.append((it + 1, float(returns.mean()), time.perf_counter() - t0))
            if progress:
                print(f"iteration {it + 1:3d}  mean return {returns.mean():8.2f}  "
                      f"best {returns.max():8.2f}  {history[-1][2]:6.1f} s", flush=True)
        seconds = time.perf_counter() - t0
    finally:
        envs.close()
    evaluation = evaluate(M, eval_episodes, horizon, seed=10_000 + seed, workers=workers)
    return dict(policy=M, history=history, eval_return=float(np.mean(evaluation)),
                eval_returns=evaluation, seconds=seconds)


def evaluate(M, episodes, horizon=1000, seed=10_000, workers=None):
    """Returns of `episodes` noise-free episodes of policy M from seeds seed, seed + 1, ..."""
    envs = PlanarVectorEnv(ENV, episodes, workers=workers)
    try:
        policies = np.broadcast_to(M, (episodes, *M.shape))
        return episode_returns(envs, policies, seed + np.arange(episodes), horizon)
    finally:
        envs.close()


def record_gif(M, path, seconds=20.0, seed=10_000):
    """An animation of policy M swimming (camera following it)."""
    from planarsim.render import export_animation
    from planarsim.render.draw import Style
    from planarsim.trajectory import Trajectory, make_recorder, record_state
    env = gymnasium.make(ENV).unwrapped
    obs, _ = env.reset(seed=seed)
    n = int(round(seconds / env.dt))
    rec = make_recorder(env.sim_model, n + 1)
    record_state(rec, 0, env.sim.state, env.sim.ws)
    for k in range(n):
        obs, *_ = env.step(np.clip(M @ obs, -1.0, 1.0))
        record_state(rec, k + 1, env.sim.state, env.sim.ws)
    traj = Trajectory.from_recorder(env.sim_model, rec)
    # the x-y plane seen from above: no ground, only a faint distance scale along x
    style = Style(ground_fill="white", terrain_color="#d0d0d0")
    export_animation(traj, env.sim_model, path, fps=10, speed=4.0, size=(3.6, 1.8), colors=16,
                     progress=False, style=style)
    return traj


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--iterations", type=int, default=40)
    ap.add_argument("--directions", type=int, default=8)
    ap.add_argument("--horizon", type=int, default=1000, help="episode length [env steps]")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--workers", type=int, default=None, help="processes (default: every core)")
    ap.add_argument("--gif", default=None, help="write an animation of the learned swimmer here")
    args = ap.parse_args()
    out = learn(args.iterations, args.directions, horizon=args.horizon, seed=args.seed,
                workers=args.workers)
    print(f"learned in {out['seconds']:.1f} s; evaluation return {out['eval_return']:.1f} "
          f"(episodes: {np.round(out['eval_returns'], 1).tolist()})")
    if args.gif:
        record_gif(out["policy"], args.gif)
        print(f"wrote {args.gif}")
