"""The stages are written once (planarsim/kernels/stages.py): the step's numbered comments,
the kernel modules' "Stage N" docstrings and the functions the list names agree with it."""
import ast
import importlib
import re
from pathlib import Path

import pytest

from planarsim.kernels.stages import STAGES, stage_number, stage_table

KERNELS = Path(__file__).resolve().parents[2] / "planarsim" / "kernels"


def _module(path):
    """Kernel source `path` as the stage list names it: dotted below planarsim/kernels/
    ("constraints.pin" for constraints/pin.py, "step" for step.py)."""
    return ".".join(path.relative_to(KERNELS).with_suffix("").parts)


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


@pytest.mark.parametrize("path", sorted(KERNELS.rglob("*.py")),
                         ids=lambda p: p.relative_to(KERNELS).as_posix())
def test_a_module_that_names_its_stage_is_listed_under_it(path):
    doc = ast.get_docstring(ast.parse(path.read_text())) or ""
    match = re.match(r"Stage (\d)", doc)
    owners = [k + 1 for k, stage in enumerate(STAGES) if _module(path) in stage[2]]
    if match:
        assert owners == [int(match.group(1))], (path.name, match.group(0), owners)
    if owners and _module(path) == STAGES[owners[0] - 1][2][0]:
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


def test_the_stages_modules_sit_in_the_kernels_folders():
    """The stage list names each module with its folder (a sub-package of planarsim/kernels/:
    geometry, constraints, solver, dynamics, checks), every such folder holds some stage's
    modules, and the table shows each module's path below planarsim/kernels/."""
    folders = {p.parent.name for p in KERNELS.glob("*/__init__.py")}
    named = set()
    for name, _, modules, _ in STAGES:
        for module in modules:
            folder, _, stem = module.rpartition(".")
            assert folder in folders, f"stage {name}: {module} is not in a folder of kernels/"
            assert (KERNELS / folder / f"{stem}.py").is_file(), (name, module)
            named.add(folder)
    assert named == folders, (named, folders)
    for line, (_, _, modules, _) in zip(stage_table().splitlines()[2:], STAGES):
        assert all(f"`{m.replace('.', '/')}.py`" in line for m in modules), line
