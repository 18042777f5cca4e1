"""README's Python code runs as written (the tour, then the compiled controller, which reuses
the tour's model), in a temporary folder."""
import re
import runpy
from pathlib import Path

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
