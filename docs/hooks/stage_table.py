"""An MkDocs hook: the line `<!-- stage-table -->` in a page becomes the table of the step's
stages that planarsim/kernels/stages.py writes (stage_table()), so the documentation's table
and the code's list of stages are one (tests/planarsim/test_stages.py checks the list against
the step and the kernel modules). stages.py is plain data: it is loaded from its file, without
importing planarsim (and numba). mkdocs.yml loads this hook (hooks:)."""
from __future__ import annotations

import importlib.util
from pathlib import Path

MARKER = "<!-- stage-table -->"


def _stage_table(root: Path) -> str:
    spec = importlib.util.spec_from_file_location("planarsim_stages", root / "planarsim" / "kernels" / "stages.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.stage_table()


def on_page_markdown(markdown, page, config, files, **kwargs):
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, _stage_table(Path(config.config_file_path).parent))
