"""The documentation's Python runs as written: every ```python block of a page in docs/, the
page's blocks in order as one script in a fresh folder (as a reader would paste them; numba
caches a function by its file). ```bash and ```text blocks are commands and output, not run
(the convention of README's blocks, tests/examples/test_readme.py). What the text says a block
gives is checked against what it gave, page by page (CHECKS)."""
import inspect
import math
import re
import runpy
from pathlib import Path

import pytest

import planarsim as ps

DOCS = Path(__file__).resolve().parents[2] / "docs"


def python_blocks(path):
    return re.findall(r"^```python\n(.*?)^```", path.read_text(), re.S | re.M)


def pages_with_python():
    return sorted(p.name for p in DOCS.glob("*.md") if python_blocks(p))


def check_tour(ns, folder):
    assert (folder / "tour.gif").stat().st_size > 0
    assert (folder / "tour.png").stat().st_size > 0
    # the tour's torso and leg are shapes that collide: whatever the controller does, no corner
    # of the torso's box ends up inside the hill
    model, traj = ns["model"], ns["traj"]
    torso = model.body("torso")
    for frame in traj.q:
        x, y, th = frame[torso]
        for dx in (-0.1, 0.1):
            for dy in (-0.25, 0.25):
                px = x + math.cos(th) * dx - math.sin(th) * dy
                py = y + math.sin(th) * dx + math.cos(th) * dy
                assert py - model.terrain.height(px) > -1e-6


def check_walkers(ns, folder):
    assert ns["biped"].GAITS == ("stand", "walk", "jump")          # as the page's comment says
    assert ns["numbers"]["audit"] and not any(ns["numbers"]["audit"].values())


def check_shapes(ns, folder):
    from planarsim.compiled import audit_counts
    audit = audit_counts(ns["sim"].ws)
    assert not any(audit.values()), audit
    ball = ns["sim"].model.body("ball")
    assert ns["traj"].q[-1, ball, 1] < 0.8          # it fell from 1 m: onto the box, which fell to the floor


def check_mjcf_gymnasium(ns, folder):
    assert ns["obs"].shape == (4, 8)                # "(4, 8)", as the vector env's comment says
    assert ns["hopper_obs"].shape == (8, 11)        # "(8, 11)": the vector entry point's
    assert type(ns["hoppers"]).__name__ == "BatchedVectorEnv"
    assert ns["model"].dt == 0.002                  # "dt 0.002 s"
    assert ns["torque"] == ns["hopper"].actuator["thigh_joint"].gear * 0.5 > 0


def check_gait_analysis(ns, folder):
    # the doubling is located where the page's text puts it (slope 0.014935 rad)
    pd = ns["pd"]
    assert pd.located and abs(pd.p - 0.014935) < 5e-7, (pd.p, pd.located, pd.note)
    assert (folder / "period1.csv").stat().st_size > 0


def check_controllers(ns, folder):
    assert ns["code"] == 0 and ns["traj"].t.shape[0] == ns["k"] > 100


def check_engine(ns, folder):
    # the accurate integrator's double pendulum: the energy error the page's comment gives
    swing, tr = ns["swing"], ns["swing_traj"]
    e = ps.total_energy(swing.model, tr.q, tr.v)
    assert abs(float(max(abs(e - e[0]))) - 1.0e-4) < 0.05e-4


CHECKS = {"tour.md": check_tour, "walkers.md": check_walkers, "shapes.md": check_shapes,
          "mjcf-gymnasium.md": check_mjcf_gymnasium, "gait-analysis.md": check_gait_analysis,
          "controllers.md": check_controllers, "engine.md": check_engine}


def test_every_page_with_python_has_its_checks():
    """A page whose blocks run is checked for what its text claims, and a checked page still has
    its blocks (a block turned into ```text would otherwise stop running unnoticed)."""
    assert pages_with_python() == sorted(CHECKS)


@pytest.mark.parametrize("page", pages_with_python())
def test_page_python_blocks_run_in_order(page, tmp_path, monkeypatch):
    if page == "mjcf-gymnasium.md":
        pytest.importorskip("gymnasium")
    monkeypatch.chdir(tmp_path)
    script = tmp_path / (page.replace("-", "_").replace(".md", "") + "_blocks.py")
    script.write_text("\n".join(python_blocks(DOCS / page)))
    namespace = runpy.run_path(str(script), run_name="docs")
    CHECKS[page](namespace, tmp_path)


def test_the_tour_gives_what_a_model_builder_needs():
    """Without reading the source: the angle convention, the shape tuples, add_box_contacts'
    arguments, terrain.slope's unit and what each contact_mode code means."""
    text = (DOCS / "tour.md").read_text()
    api = text[text.index("## What a model builder needs"):text.index("## When a run stops")]
    api = " ".join(api.split())
    assert "counter-clockwise from the world's x axis" in api
    for shape in ('("circle", center, r)', '("capsule", p0, p1, r)',
                  '("box", center, width, height[, angle])', '("polygon", [(x, y), ...])'):
        assert shape in api
    signature = str(inspect.signature(ps.ModelBuilder.add_box_contacts)).replace("self, ", "")
    assert f"add_box_contacts{signature.split(' ->')[0]}" in api
    assert "`terrain.slope(angle_deg, height=0.0)` takes degrees" in api
    from planarsim.kernels import codes
    for code, meaning in ((codes.MODE_FREE, "free"), (codes.MODE_PINNED, "pinned"),
                          (codes.MODE_SLIDING, "sliding")):
        assert f"`{code}` {meaning}" in api
    assert "in a recording `-1` marks" in api


def test_pages_name_no_file_outside_the_repository():
    """Users have the repository only: no page points into a folder beside it or at an issue
    tracker."""
    for page in list(DOCS.rglob("*.md")) + [DOCS.parent / "README.md", DOCS.parent / "mkdocs.yml"]:
        text = page.read_text()
        assert "../shared" not in text and "shared/" not in text, page
        assert not re.search(r"\bissues?\b #?\d|/issues\b|\bissue tracker\b", text, re.I), page


def test_docstrings_keep_their_layout_in_the_api_reference():
    """docs/hooks/plain_docstrings.py (the API reference's griffe extension): a `>>>` session
    becomes a Python console block, an aligned `name : meaning` table and an indented
    continuation keep their lines in a text block, a dashed section title turns bold, and
    running prose stays Markdown."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("plain_docstrings", DOCS / "hooks" / "plain_docstrings.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    text = inspect.cleandoc('''Prose that wraps
        onto a second line.

        >>> 1 + 1
        2

        Parameters
        ----------
        q : (n_body, 3) [m]     positions
        v : (n_body, 3) [m/s]   velocities, continued
            on an indented line''')
    md = hook.to_markdown(text)
    assert md.startswith("Prose that wraps\nonto a second line.\n\n```pycon\n>>> 1 + 1\n2\n```")
    assert "**Parameters**\n\n```text\nq : (n_body, 3) [m]     positions\n" in md
    assert md.endswith("    on an indented line\n```")


def test_the_stage_table_is_the_codes_own():
    """docs/engine.md takes its table of the step's stages from planarsim/kernels/stages.py (the
    hook docs/hooks/stage_table.py puts stage_table() where the marker stands) and keeps no
    hand-written copy of it."""
    text = (DOCS / "engine.md").read_text()
    assert text.count("<!-- stage-table -->") == 1
    assert "| stage |" not in text
    hooks = (DOCS.parent / "mkdocs.yml").read_text()
    assert "docs/hooks/stage_table.py" in hooks
