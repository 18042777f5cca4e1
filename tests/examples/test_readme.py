"""README's Python code runs as written (the tour, then the compiled controller, which reuses
the tour's model), in a temporary folder."""
import math
import re
import runpy
from pathlib import Path

import planarsim as ps

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_blocks_run_in_order(tmp_path, monkeypatch):
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert len(blocks) >= 2
    monkeypatch.chdir(tmp_path)
    # one script file, as a reader would paste it (numba caches a function by its file)
    script = tmp_path / "readme_blocks.py"
    script.write_text("\n".join(blocks))
    namespace = runpy.run_path(str(script), run_name="readme")
    assert (tmp_path / "tour.gif").stat().st_size > 0
    assert (tmp_path / "tour.png").stat().st_size > 0
    assert namespace["code"] == 0 and namespace["traj"].t.shape[0] == namespace["k"]
    # the accurate integrator's double pendulum: the energy error README's comment gives
    swing, tr = namespace["swing"], namespace["swing_traj"]
    e = ps.total_energy(swing.model, tr.q, tr.v)
    assert abs(float(max(abs(e - e[0]))) - 1.0e-4) < 0.05e-4
    # the gait analysis example's doubling is located, where README's text puts it
    pd = namespace["pd"]
    assert pd.located and abs(pd.p - 0.014935) < 5e-7, (pd.p, pd.located, pd.note)
    # the tour's torso and leg are shapes that collide: whatever the controller does, no corner
    # of the torso's box ends up inside the hill (it used to fall 0.5 m into it)
    model, traj = namespace["model"], namespace["traj"]
    ground = model.terrain
    torso = model.body("torso")
    for frame in traj.q:
        x, y, th = frame[torso]
        for dx in (-0.1, 0.1):
            for dy in (-0.25, 0.25):
                px = x + math.cos(th) * dx - math.sin(th) * dy
                py = y + math.sin(th) * dx + math.cos(th) * dy
                assert py - ground.height(px) > -1e-6


def test_readme_api_section_gives_what_a_model_builder_needs():
    """Without reading the source: the angle convention, the shape tuples, add_box_contacts'
    arguments, terrain.slope's unit and what each contact_mode code means."""
    text = README.read_text()
    api = text[text.index("## A five-minute tour of the API"):text.index("## Shapes that collide")]
    api = " ".join(api.split())
    assert "counter-clockwise from the world's x axis" in api
    for shape in ('("circle", center, r)', '("capsule", p0, p1, r)',
                  '("box", center, width, height[, angle])', '("polygon", [(x, y), ...])'):
        assert shape in api
    import inspect

    signature = str(inspect.signature(ps.ModelBuilder.add_box_contacts)).replace("self, ", "")
    assert f"add_box_contacts{signature.split(' ->')[0]}" in api
    assert "`terrain.slope(angle_deg, height=0.0)` takes degrees" in api
    from planarsim.kernels import codes
    for code, meaning in ((codes.MODE_FREE, "free"), (codes.MODE_PINNED, "pinned"),
                          (codes.MODE_SLIDING, "sliding"), (-1, "in a recording `-1` marks")):
        assert (f"`{code}` {meaning}" in api) or (meaning.endswith("marks") and meaning in api)


def test_readme_gives_the_expected_time_of_both_commands(monkeypatch, capsys):
    """README's expected times agree with the figures they come from: each 'about N minutes'
    is its measured seconds rounded, command 2's parts add up to its total, the first compile's
    quiet-machine figure is the one the program quotes (compiled.TYPICAL_COMPILE_S), the
    program's message reads as README quotes it, and tests/README.md gives the same time for
    the test run. (The times themselves are measured by hand: benchmarks/startup.py.)"""
    from planarsim import compiled
    from walkers import cli
    text = README.read_text()
    part = " ".join(text[text.index("## Two commands"):text.index("## The command line")].split())
    minutes = {}
    for k in (1, 2):
        about, unit, measured = re.search(rf"command {k}: about (\d+) (minutes?) \((\d+) s measured\)", part).groups()
        assert int(about) == round(int(measured) / 60), (k, about, measured)
        assert unit == ("minute" if int(about) == 1 else "minutes"), (k, unit)
        minutes[k] = int(about)
    # command 2: the install and the tests add up to the measured total (README rounds each)
    total, install, tests = map(int, re.search(
        r"command 2: about \d+ minutes \((\d+) s measured\): the install with the test extras about (\d+) s, "
        r"then the tests (\d+) s", part).groups())
    assert abs(install + tests - total) <= 5, (install, tests, total)
    # the first compile on a quiet machine: what the program says where it has measured none
    quiet = float(re.search(r"first compile of the engine \(about (\d+) s on a quiet machine", part).group(1))
    assert quiet == compiled.TYPICAL_COMPILE_S
    # the program's message after a first compile, as README quotes it (N: the seconds)
    monkeypatch.setattr(compiled, "record_compile", lambda seconds: None)   # keep this machine's record
    cli._said_compiled(37.4)
    quoted = re.search(r"\(`(first compile: [^`]*)`\)", part).group(1)
    assert quoted.replace("N", "37") in capsys.readouterr().err, quoted
    # tests/README.md states the test run's time in words: the same minutes as command 2's
    words = {"five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9, "ten": 10}
    said = re.search(r"runs everything \(about (\w+) minutes", (README.parent / "tests" / "README.md").read_text())
    assert words.get(said.group(1), said.group(1)) in (minutes[2], str(minutes[2])), said.group(0)
    assert "about half a minute" not in text
