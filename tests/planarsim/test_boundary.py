"""The engine/walker boundary: walkers, examples and benchmarks use the engine only through its
public modules (planarsim.compiled for compiled code), never planarsim.kernels or a name
that starts with an underscore."""
import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
USERS = ["walkers", "examples"]


def _imports(path):
    """(module, name) for every `import module` / `from module import name` in a file."""
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, None
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            for a in node.names:
                yield node.module, a.name


def _private_attributes(path):
    """planarsim objects' private attributes used in a file (sim._u0, ps._x)."""
    tree = ast.parse(path.read_text(), str(path))
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_")
                and not node.attr.startswith("__") and isinstance(node.value, ast.Name)
                and node.value.id in ("sim", "ps", "planarsim", "simulator")):
            yield f"{node.value.id}.{node.attr}"


@pytest.mark.parametrize("folder", USERS)
def test_users_of_the_engine_stay_on_its_public_side(folder):
    bad = []
    for path in sorted((ROOT / folder).rglob("*.py")):
        for module, name in _imports(path):
            if not module.startswith("planarsim"):
                continue
            if module.startswith("planarsim.kernels") or any(p.startswith("_") for p in module.split(".")):
                bad.append(f"{path.relative_to(ROOT)}: import from {module}")
            elif name is not None and name.startswith("_") and not name.startswith("__"):
                bad.append(f"{path.relative_to(ROOT)}: {module}.{name}")
        bad += [f"{path.relative_to(ROOT)}: {a}" for a in _private_attributes(path)]
    assert not bad, "\n".join(bad)


def test_the_engine_never_imports_walkers_or_benchmarks():
    bad = []
    for path in sorted((ROOT / "planarsim").rglob("*.py")):
        for module, name in _imports(path):
            top = module.split(".")[0]
            if top in ("walkers", "benchmarks"):
                bad.append(f"{path.relative_to(ROOT)}: import {module}")
    assert not bad, "\n".join(bad)
