"""The stages are written once (planarsim/kernels/stages.py): the step's numbered comments,
the kernel modules' "Stage N" docstrings and the functions the list names agree with it."""
import ast
import importlib
import re
from pathlib import Path

import pytest

from planarsim.kernels.stages import STAGES, stage_number, stage_table

KERNELS = Path(__file__).resolve().parents[2] / "planarsim" / "kernels"


def test_the_steps_numbered_comments_name_the_stages():
    text = (KERNELS / "step.py").read_text()
    found = re.findall(r"# (\d)(?:-(\d))?\. ([a-z][^\n]*)", text)
    assert found, "no numbered stage comments in step.py"
    seen = set()
    for first, last, words in found:
        numbers = range(int(first), int(last or first) + 1)
        names = [STAGES[k - 1][0] for k in numbers]
        if len(names) == 1:
            assert words.startswith(names[0]), (first, words, names)
        else:
            assert words.startswith(", ".join(names)), (first, last, words, names)
        seen.update(numbers)
    assert seen == set(range(1, len(STAGES) + 1))


@pytest.mark.parametrize("path", sorted(KERNELS.glob("*.py")), ids=lambda p: p.name)
def test_a_module_that_names_its_stage_is_listed_under_it(path):
    doc = ast.get_docstring(ast.parse(path.read_text())) or ""
    match = re.match(r"Stage (\d)", doc)
    owners = [k + 1 for k, stage in enumerate(STAGES) if path.stem in stage[2]]
    if match:
        assert owners == [int(match.group(1))], (path.name, match.group(0), owners)
    if owners and path.stem == STAGES[owners[0] - 1][2][0]:
        # a stage's first module says which stage it is
        assert match, f"{path.name} owns stage {owners[0]} but its docstring does not say so"


@pytest.mark.parametrize("k", range(len(STAGES)))
def test_the_functions_the_list_names_are_in_its_modules(k):
    name, _, modules, functions = STAGES[k]
    defined = set()
    for module in modules:
        defined.update(n for n in vars(importlib.import_module(f"planarsim.kernels.{module}")))
    missing = [f for f in functions if f not in defined]
    assert not missing, (name, missing)


def test_stage_table_and_numbers():
    table = stage_table().splitlines()
    assert len(table) == 2 + len(STAGES)
    assert all(table[2 + k].startswith(f"| {k + 1}. {s[0]} |") for k, s in enumerate(STAGES))
    assert stage_number("guards") == len(STAGES)
    with pytest.raises(KeyError, match="no stage"):
        stage_number("broadphase")
