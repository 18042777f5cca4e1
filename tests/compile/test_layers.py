"""planarsim's layers, read from its sources with ast: no import circle of more than two
modules (imports inside functions counted too), a compiler layer (planarsim/compile) that
imports nothing from the rest of planarsim, and numba's classes left as they are."""
import ast
from pathlib import Path

import planarsim

PACKAGE = Path(planarsim.__file__).resolve().parent
REPOSITORY = PACKAGE.parent


def _modules(package: Path) -> dict:
    """{dotted module name: (path, is a package's __init__)} of every .py file below package."""
    found = {}
    for path in package.rglob("*.py"):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts = parts[:-1]
        found[".".join(parts)] = (path, is_package)
    return found


def _imported(module: str, node, modules: dict) -> list:
    """The modules of `modules` that import statement `node` of `module` imports: relative
    imports resolved; ``from pkg import name`` imports pkg.name where that is a module, else
    pkg; an import of a module not in `modules` (numpy, a name below a module) goes to the
    nearest enclosing one that is."""
    _, is_package = modules[module]
    if isinstance(node, ast.Import):
        targets = [alias.name for alias in node.names]
    else:
        if node.level:
            base = module.split(".") if is_package else module.split(".")[:-1]
            base = base[:len(base) - node.level + 1]
            base = ".".join(base + ([node.module] if node.module else []))
        else:
            base = node.module
        targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base
                   for alias in node.names]
    found = []
    for target in targets:
        while target not in modules and "." in target:
            target = target.rsplit(".", 1)[0]
        if target in modules and target != module:
            found.append(target)
    return found


def import_graph(package: Path) -> dict:
    """{module: set of the modules it imports} for every module below `package`: every import
    statement, at the top of a file or inside a function, a class or a branch."""
    modules = _modules(package)
    graph = {}
    for module, (path, _) in modules.items():
        tree = ast.parse(path.read_text(), str(path))
        graph[module] = {target for node in ast.walk(tree)
                         if isinstance(node, (ast.Import, ast.ImportFrom))
                         for target in _imported(module, node, modules)}
    return graph


def strongly_connected(graph: dict) -> list:
    """The strongly connected components of `graph` (Tarjan's algorithm, without recursion)."""
    index, low, on_stack, stack, components = {}, {}, set(), [], []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = set()
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.add(member)
                        if member == node:
                            break
                    components.append(component)
    return components


def test_the_graph_reader_finds_circles_of_every_kind_of_import(tmp_path):
    """The reader itself: a circle closed by a relative import inside a function, by ``from
    package import module`` and by an absolute import is found; a chain without one is not."""
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from . import b\n")
    (pkg / "b.py").write_text("def f():\n    from .sub.c import g\n")
    (pkg / "sub" / "__init__.py").write_text("")
    (pkg / "sub" / "c.py").write_text("import pkg.a\nfrom ..d import x\n")
    (pkg / "d.py").write_text("import numpy\nx = 1\n")
    graph = import_graph(pkg)
    assert graph["pkg.a"] == {"pkg.b"} and graph["pkg.b"] == {"pkg.sub.c"}
    assert graph["pkg.sub.c"] == {"pkg.a", "pkg.d"} and graph["pkg.d"] == set()
    largest = max(strongly_connected(graph), key=len)
    assert largest == {"pkg.a", "pkg.b", "pkg.sub.c"}
    (pkg / "sub" / "c.py").write_text("from ..d import x\n")
    assert max(len(c) for c in strongly_connected(import_graph(pkg))) == 1


def test_no_import_circle_ties_more_than_two_modules():
    graph = import_graph(PACKAGE)
    assert len(graph) > 100 and "planarsim.link.step" in graph["planarsim.sim"]
    largest = max(strongly_connected(graph), key=len)
    assert len(largest) <= 2, f"an import circle of {len(largest)} modules: {sorted(largest)}"


def test_the_compiler_layer_imports_nothing_from_the_rest_of_planarsim():
    graph = import_graph(PACKAGE)
    layer = [m for m in graph if m == "planarsim.compile" or m.startswith("planarsim.compile.")]
    assert len(layer) >= 8
    outside = {(m, t) for m in layer for t in graph[m]
               if not (t == "planarsim.compile" or t.startswith("planarsim.compile."))}
    assert not outside, f"planarsim/compile imports from the rest of planarsim: {sorted(outside)}"
    # nor names a module of the rest of planarsim for importlib
    for m in layer:
        path = PACKAGE.joinpath(*m.split(".")[1:]) / "__init__.py"
        path = path if path.exists() else path.parent.with_suffix(".py")
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                name = node.value
                assert not (name.startswith("planarsim.") and not name.startswith("planarsim.compile")), (
                    f"{path.name} names {name}")


def _numba_names(tree) -> set:
    """Names bound to numba objects in a module: ``from numba... import X`` and ``import
    numba...`` (as their alias)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "numba":
            names |= {alias.asname or alias.name for alias in node.names}
        elif isinstance(node, ast.Import):
            names |= {(alias.asname or alias.name).split(".")[0] for alias in node.names
                      if alias.name.split(".")[0] == "numba"}
    return names


def _root(node):
    while isinstance(node, ast.Attribute):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def numba_assignments(tree) -> list:
    """(line, name) of each assignment to an attribute of a numba object in module `tree`:
    ``name.attr = ...`` (or augmented, or annotated) and ``setattr(name, ...)``, name bound
    by an import from numba."""
    numba = _numba_names(tree)
    found = []
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
              and node.func.id == "setattr" and node.args):
            targets = [ast.Attribute(value=node.args[0], attr="?")]
        for target in targets:
            if isinstance(target, ast.Attribute) and _root(target) in numba:
                found.append((node.lineno, _root(target)))
    return found


def test_the_numba_assignment_reader_finds_each_form():
    source = ("from numba.core.targetconfig import TargetConfig\n"
              "import numba.core.codegen as cg\n"
              "from numba.core import caching\n"
              "TargetConfig.__hash__ = lambda self: 0\n"
              "cg.JITCodeLibrary.finalize = None\n"
              "setattr(caching, 'Cache', None)\n"
              "mine = object()\n"
              "mine.x = 1\n")
    assert numba_assignments(ast.parse(source)) == [(4, "TargetConfig"), (5, "cg"), (6, "caching")]


def test_no_attribute_of_numba_is_assigned_anywhere_in_the_repository():
    """planarsim changes none of numba's classes or modules for the whole process: no
    ``numba_thing.attr = ...`` and no setattr(numba_thing, ...) in any source (tests may
    monkeypatch numba's config through pytest, which puts it back)."""
    checked = 0
    for path in REPOSITORY.rglob("*.py"):
        if ".venv" in path.parts or "site-packages" in path.parts:
            continue
        tree = ast.parse(path.read_text(), str(path))
        if _numba_names(tree):
            checked += 1
        found = numba_assignments(tree)
        assert not found, f"{path.relative_to(REPOSITORY)} assigns attributes of numba's {found}"
    assert checked > 10
