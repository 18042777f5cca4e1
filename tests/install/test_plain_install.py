"""README's first command installs planarsim without the test extra: every walker, and the
commands a newcomer tries first, must work from that install alone (the test extra brings
scipy, dask and hypothesis, which would hide a missing dependency).

Builds a fresh venv with `pip install -e .` (no extras) from this checkout; pip's cache makes
a repeat quick. The numba cache is the checkout's own, so the runs load compiled code."""
import json
import os
import subprocess
import sys
import venv
from pathlib import Path

import pytest

import walkers

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def plain_venv(tmp_path_factory):
    env_dir = tmp_path_factory.mktemp("plain") / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    py = env_dir / "bin" / "python"
    done = subprocess.run([str(py), "-m", "pip", "install", "-q", "-e", str(ROOT)],
                          capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    return env_dir


def _run(env_dir, *args, cwd):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    return subprocess.run([str(env_dir / "bin" / "planarsim"), *map(str, args)], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=600)


def test_the_plain_install_lacks_the_test_extra(plain_venv):
    py = plain_venv / "bin" / "python"
    probe = subprocess.run([str(py), "-c", "import importlib.util as u; "
                            "print(u.find_spec('hypothesis') is None, u.find_spec('dask') is None)"],
                           capture_output=True, text=True)
    assert probe.stdout.split() == ["True", "True"], (probe.stdout, probe.stderr)


@pytest.mark.parametrize("walker", sorted(walkers.WALKERS))
def test_every_walker_runs_from_the_plain_install(plain_venv, walker, tmp_path):
    done = _run(plain_venv, "run", walker, "--duration", "0.5", "--out", tmp_path / "w.gif",
                "--plot", tmp_path / "w.png", "--json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    summary = json.loads(done.stdout)
    assert summary["walker"] == walker and summary["fell"] is False
    assert (tmp_path / "w.gif").stat().st_size > 0 and (tmp_path / "w.png").stat().st_size > 0


def test_tune_and_params_from_the_plain_install(plain_venv, tmp_path):
    done = _run(plain_venv, "tune", "simple-biped", "--budget", "4", "--popsize", "4",
                "--duration", "0.5", "--workers", "1", "--out", tmp_path / "t.json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    done = _run(plain_venv, "run", "simple-biped", "--duration", "0.5", "--json", "--params",
                tmp_path / "t.json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    done = _run(plain_venv, "params", "ranger", cwd=tmp_path)
    assert done.returncode == 0 and "push_gain" in done.stdout
