"""The fast mode (planarsim/compile/fast.py, planarsim/link/fast_step.py): its check of numba's internals,
kernels' own code library, the step's linkage across processes and the cache invalidation
after a kernel's source changes."""
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numba
import pytest

from planarsim.compile import FAST, MODE, kernel, mode, numba_check

if MODE != FAST:
    pytest.skip("the fast mode's own checks (this process compiles in another mode)",
                allow_module_level=True)

from planarsim.compile import fast  # noqa: E402


def _run(code, *args, path=(), cwd=None, env=None):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([*map(str, path), os.getcwd()]),
               **(env or {}))
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code), *args], capture_output=True,
                         text=True, env=env, cwd=cwd or os.getcwd())
    assert out.returncode == 0, (args, out.returncode, out.stderr[-2000:])
    return out.stdout.split()


def test_installed_numba_has_every_internal_the_layer_uses():
    assert numba_check.changed_internals() == []


def test_a_changed_internal_falls_back_to_plain_numba_naming_it_and_the_numba_version(monkeypatch):
    from numba.core import cgutils
    monkeypatch.delattr(cgutils, "unpack_tuple")
    with pytest.warns(RuntimeWarning) as said:
        chosen = mode.choose_mode({}, False, numba_check.changed_internals)
    assert chosen == mode.PLAIN
    text = str(said[0].message)
    assert f"numba {numba.__version__}" in text
    assert "numba.core.cgutils.unpack_tuple" in text and "plain numba" in text


def test_kernels_lower_into_the_kernel_library_and_refuse_python_calls():
    @kernel
    def twice(x):
        return 2.0 * x

    @numba.njit
    def caller(x):
        return twice(x) + 1.0

    assert caller(1.5) == 4.0
    (cres,) = twice.overloads.values()
    assert type(cres.library) is fast.KernelCodeLibrary   # not numba's own (slow cold start)
    with pytest.raises(TypeError, match="compiled kernel"):
        twice(1.5)


def test_a_kernel_compiles_once_for_all_constant_arguments():
    """numba would compile a kernel once per constant value passed to it (a row kind, an audit
    rule): 177 compilations of the step's kernels instead of 122, 8 s of a cold start."""
    @kernel
    def scaled(x, k):
        return k * x

    @numba.njit
    def caller(x):
        return scaled(x, 1) + scaled(x, 2) + scaled(x, 3)

    assert caller(1.5) == 9.0
    assert len(scaled.overloads) == 1


def test_cached_code_reaching_the_step_through_other_cached_code_loads(tmp_path):
    """F calls the step, G calls F, all cached. Process 1 compiles F; process 2 loads F from
    the cache and compiles G; process 3 loads G alone from the cache. In each, the jit
    dispatcher must have published the step's address before its cached machine code is
    loaded (else the process dies jumping to an unresolved symbol)."""
    (tmp_path / "fmod.py").write_text(textwrap.dedent("""
        from planarsim.compiled import jit, step

        @jit
        def F(m, s, ws, opt, u):
            return step(m, s, ws, opt, u)
    """))
    (tmp_path / "gmod.py").write_text(textwrap.dedent("""
        from planarsim.compiled import jit
        from fmod import F

        @jit
        def G(m, s, ws, opt, u):
            return F(m, s, ws, opt, u) + 10
    """))
    run = """
        import sys
        mod = __import__(sys.argv[1])   # first: nothing else has loaded the step
        import numpy as np
        from planarsim.model import Model
        from planarsim.options import StepOptions
        from planarsim.state import make_state, make_workspace
        from tests.planarsim.test_reliability import two_link_on_hills
        model = two_link_on_hills()
        s, ws = make_state(model), make_workspace(model)
        fn = getattr(mod, sys.argv[2])
        print(fn(model.arrays, s, ws, StepOptions(), np.zeros(model.n_act)), s.step[0],
              sum(fn.stats.cache_hits.values()))
    """
    outs = [_run(run, mod, fn, path=[tmp_path]) for mod, fn in (("fmod", "F"), ("gmod", "G"), ("gmod", "G"))]
    assert outs[0] == ["0", "1", "0"]      # F compiled, one step taken
    assert outs[1] == ["10", "1", "0"]     # G compiled (F from the cache)
    assert outs[2] == ["10", "1", "1"]     # G from the cache, and the step ran


def test_threads_first_calling_cached_rollouts_wait_for_the_step():
    """A fresh process whose first compiled calls are two walkers' cached rollouts, started
    at once from two threads: one publishes the step, the other waits for it (a thread that
    went on would load code naming a symbol not yet published)."""
    import walkers
    for name in ("simple-biped", "rimless-wheel"):
        walkers.load(name).simulate(0.01)          # the caches are warm
    code = textwrap.dedent("""
        import threading, walkers
        out = {}
        def go(name):
            out[name] = walkers.load(name).simulate(0.2)[1]["fell"]
        names = ("simple-biped", "rimless-wheel")
        mods = [walkers.load(n) for n in names]
        threads = [threading.Thread(target=go, args=(n,)) for n in names]
        for t in threads: t.start()
        for t in threads: t.join()
        print(sorted(out.items()))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "('rimless-wheel', False), ('simple-biped', False)" in done.stdout


def test_a_cold_cache_compiles_the_step_for_a_plain_njit_caller_first(tmp_path):
    """A first-ever process (an empty numba cache) whose first compiled code is a plain
    numba.njit function calling the step: typing it compiles and publishes the step, whose
    own compile goes through jit dispatchers (terrain) that must not start it again, while a
    child process compiles the step's parts. A walker's rollout then runs in the same
    process. About half a minute: a full compile."""
    code = textwrap.dedent("""
        import numpy as np
        from numba import njit
        import planarsim as ps, walkers
        from planarsim.compiled import step
        from planarsim.state import make_workspace
        @njit
        def one(m, s, ws, opt, u):
            return step(m, s, ws, opt, u)
        b = ps.ModelBuilder()
        body = b.add_body("b", 1.0, 0.1, pos=(0.5, 0.0))
        b.add_pin("p", None, body, anchor_world=(0.0, 0.0))
        model = b.compile()
        s, ws = ps.make_state(model), make_workspace(model)
        print("step", one(model.arrays, s, ws, ps.StepOptions(), np.zeros(0)))
        print("fell", walkers.load("rimless-wheel").simulate(0.5)[1]["fell"])
        from planarsim.compile.parts import PARTS
        print("parts from the child", PARTS.cfunc.cache_hits)
    """)
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("PLANARSIM_COMPILE_CHILD", None)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "step 0" in done.stdout and "fell False" in done.stdout
    # the step's parts were compiled in a child process (compile/parts.py), which cached them
    # for this one to load
    assert "parts from the child 1" in done.stdout, done.stdout


def test_editing_a_kernel_recompiles_its_cached_callers(tmp_path):
    """numba checks a cached function against its own file only: b.run calls kernel a.value,
    and after a.py changes, drop_stale_caches (on the package's import) must clear b's cache."""
    pkg = tmp_path / "kpkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from planarsim.compiled import drop_stale_caches\n"
                                     "drop_stale_caches(__path__[0])\n")
    (pkg / "b.py").write_text(textwrap.dedent("""
        from planarsim.compiled import jit
        from .a import value

        @jit
        def run(x):
            return value(x)
    """))
    code = "from kpkg.b import run; print(run(1.0), sum(run.stats.cache_hits.values()))"
    outs = []
    for k in (1, 1, 2):
        (pkg / "a.py").write_text(f"from planarsim.compiled import kernel\n\n@kernel\n"
                                  f"def value(x):\n    return x + {k}\n")
        outs.append(_run(code, path=[tmp_path]))
    assert outs == [["2.0", "0"], ["2.0", "1"], ["3.0", "0"]]


def test_editing_a_kernel_clears_its_callers_caches_in_numba_cache_dir_too(tmp_path):
    """With NUMBA_CACHE_DIR set numba keeps the caches there, not next to the sources: b.run
    (cached) calls a.value, and after a.py changes b's stale machine code must not be loaded
    from there either (its result would be the old one)."""
    pkg = tmp_path / "upkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from planarsim.compiled import drop_stale_caches\n"
                                     "drop_stale_caches(__path__[0])\n")
    (pkg / "b.py").write_text(textwrap.dedent("""
        import numba
        from .a import value

        @numba.njit(cache=True)
        def run(x):
            return value(x)
    """))
    code = "from upkg.b import run; print(run(1.0), sum(run.stats.cache_hits.values()))"
    cache = tmp_path / "numba_cache"
    outs = []
    for k in (1, 1, 2):
        (pkg / "a.py").write_text(f"import numba\n\n@numba.njit(cache=True)\n"
                                  f"def value(x):\n    return x + {k}\n")
        outs.append(_run(code, path=[tmp_path], env={"NUMBA_CACHE_DIR": str(cache)}))
    assert outs == [["2.0", "0"], ["2.0", "1"], ["3.0", "0"]]
    assert not list(pkg.rglob("*.nbi")) and list(cache.rglob("*.nbi"))   # written there


_BRANCHY_IR = r'''
declare double @g(double)
define double @f(double %x, double %y) {
entry:
  %c = fcmp olt double %x, %y
  br i1 %c, label %a, label %b
a:
  %r1 = call double @g(double %x)
  br label %m
b:
  %r2 = call double @g(double %y)
  %r3 = fadd double %r2, 1.0
  br label %m
m:
  %r = phi double [%r1, %a], [%r3, %b]
  %c2 = fcmp olt double %r, 0.0
  br i1 %c2, label %a2, label %e
a2:
  %r4 = call double @g(double %r)
  ret double %r4
e:
  ret double %r
}
'''


def _alignments():
    """(alignment directives, 64-byte ones) LLVM emits now for a small function with branches."""
    import llvmlite.binding as llvm
    llvm.initialize_native_target()
    llvm.initialize_native_asmprinter()
    machine = llvm.Target.from_default_triple().create_target_machine(opt=3)
    text = machine.emit_assembly(llvm.parse_assembly(_BRANCHY_IR))
    return text.count(".p2align"), text.count(".p2align\t6") + text.count(".p2align 6")


def test_code_layout_aligns_functions_and_blocks_inside_and_nothing_after():
    from planarsim.compile.fast import code_layout
    plain = _alignments()
    with code_layout():
        with code_layout():      # reentrant: the inner exit keeps the layout
            pass
        aligned = _alignments()
    assert aligned[0] > plain[0], "no block alignment inside code_layout (-align-all-nofallthru-blocks)"
    assert aligned[1] > plain[1], "no 64-byte alignment inside code_layout (-align-all-functions)"
    assert _alignments() == plain, "the layout options stayed set after code_layout"


def test_planarsim_compiles_its_step_and_callers_under_code_layout():
    """The step's C function and every planarsim jit caller are compiled (or loaded) with the
    layout options set, and LLVM's defaults are back after each (fresh process: the step is
    loaded there)."""
    out = _run("""
        import llvmlite.binding as llvm
        calls = []
        real = llvm.set_option
        llvm.set_option = lambda name, option: (calls.append(option), real(name, option))[1]
        from planarsim.compile.fast import LLVM_DEFAULTS, PLANARSIM_LLVM
        from planarsim.link.step import load_step
        load_step()
        step_calls = list(calls)
        del calls[:]
        from planarsim.compile import fast

        @fast._caller_decorator(cache=False)     # planarsim's jit, uncached (no source file)
        def twice(x):
            return 2.0 * x
        twice(1.5)
        ok_step = step_calls == list(PLANARSIM_LLVM) + list(LLVM_DEFAULTS)
        ok_jit = calls == list(PLANARSIM_LLVM) + list(LLVM_DEFAULTS)
        print(ok_step, ok_jit)
    """)
    assert out == ["True", "True"], out


def test_a_callers_caches_follow_only_the_sources_its_code_can_inline(tmp_path):
    """drop_stale_caches(folder) of a package of compiled callers hashes the kernel modules
    its files import (through planarsim.compiled or planarsim.kernels) and theirs in turn; the
    step is reached by address, so the kernels only the step uses are not among them. It
    hashes too the modules of its own top-level package outside it that it imports (a shared
    helper: walkers/common for a walker) and planarsim's modules with compiled code, with the
    kernels those import (planarsim/half_step.py inlines kernels/dynamics/forces.py)."""
    from planarsim.compiled import caller_sources
    top = tmp_path / "top"
    own, shared = top / "own", top / "shared"
    for package in (top, own, shared):
        package.mkdir(exist_ok=True)
        (package / "__init__.py").write_text("")
    (own / "a.py").write_text("from planarsim.compiled import jit, step, height\n")
    assert caller_sources(own) == ({"geometry.terrain"}, set())
    (own / "b.py").write_text("from planarsim.kernels.geometry.pair import shape_contact_mode\n")
    kernels, _ = caller_sources(own)
    assert {"geometry.terrain", "geometry.pair", "geometry.collide", "math2d", "codes"} <= kernels    # pair's own imports
    assert not kernels & {"solver.lcp", "solver.complementarity", "step", "solver.solve", "checks.audit"}
    (own / "c.py").write_text("from planarsim import compiled\n"
                              "from planarsim.actuators import motor_torque\n"
                              "from planarsim.model import Model\n"
                              "from top.shared.helpers import clamp\n")
    (shared / "helpers.py").write_text("from .more import LIMIT\n")
    (shared / "more.py").write_text("LIMIT = 2.0\n")
    kernels, files = caller_sources(own)
    assert {"record", "dynamics.forces", "geometry.terrain", "geometry.pair"} <= kernels
    import planarsim
    actuators = Path(planarsim.__file__).resolve().parent / "actuators.py"
    assert files == {actuators, shared / "helpers.py", shared / "more.py"}   # not model.py
    # a planarsim module with compiled code brings the kernels its code inlines
    other = top / "other"
    other.mkdir()
    (other / "__init__.py").write_text("")
    (other / "d.py").write_text("from planarsim.half_step import kick\n")
    kernels, files = caller_sources(other)
    assert "dynamics.forces" in kernels and files == {actuators.parent / "half_step.py"}


def test_jit_functions_cache_in_files_of_their_own_which_plain_numba_never_loads():
    """The fast mode's compiled callers reach the step by a published symbol; plain numba's
    inline it. Their cache keys are the same, so the fast mode names its files apart: a
    process of either mode never loads the other's machine code."""
    import numba

    from walkers.simple_biped.rollout import rollout_simple_biped
    fast = rollout_simple_biped._cache._cache_file._index_name
    plain = numba.njit(cache=True)(rollout_simple_biped.py_func)._cache._cache_file._index_name
    assert fast.endswith("-fast.nbi") and not plain.endswith("-fast.nbi")
    assert fast.replace("-fast.nbi", ".nbi") == plain


def test_the_kernels_cache_folder_is_numbas_own_with_numba_cache_dir_set(tmp_path, monkeypatch):
    """planarsim.compiled.kernel_cache (the first-run message reads it) and the stale-cache
    clearing look where numba writes: NUMBA_CACHE_DIR's folder for the step's source, if set."""
    from numba.core import caching, config

    from planarsim.compile.caches import cache_folder
    from planarsim.link import fast_step
    source = Path(fast_step.__file__)
    if not config.CACHE_DIR:
        assert cache_folder(source.parent) == Path(os.path.abspath(source.parent)) / "__pycache__"
    monkeypatch.setattr(config, "CACHE_DIR", str(tmp_path))
    numbas = caching.UserProvidedCacheLocator(fast_step._step_c, str(source)).get_cache_path()
    assert cache_folder(source.parent) == Path(numbas)


@pytest.mark.parametrize("blocked", ["the folder", "its folder for the sources"])
def test_a_numba_cache_dir_that_cannot_be_written_is_named_and_numbas_fallback_used(
        tmp_path, monkeypatch, blocked):
    """numba passes over a NUMBA_CACHE_DIR it cannot write (the folder itself below a regular
    file, or numba's folder for the sources inside it a regular file) and caches in the next
    place, silently: the first-run message and the stale-cache clearing look there too (not
    in the unusable folder), and a RuntimeWarning names the folder."""
    from numba.core import caching, config

    from planarsim.compile import caches
    from planarsim.link import fast_step
    source = Path(fast_step.__file__)
    if blocked == "the folder":
        blocker = tmp_path / "a_file"
        blocker.write_text("not a folder")
        unusable = str(blocker / "cache")
    else:
        unusable = str(tmp_path / "cache")
    monkeypatch.setattr(config, "CACHE_DIR", unusable)
    monkeypatch.setattr(caches, "_WARNED_CACHE_DIRS", set())
    if blocked != "the folder":
        own = Path(caching.UserProvidedCacheLocator(fast_step._step_c, str(source)).get_cache_path())
        own.parent.mkdir(parents=True)
        own.write_text("not a folder")
    with pytest.warns(RuntimeWarning, match="NUMBA_CACHE_DIR=.*cannot be"):
        folder = caches.cache_folder(source.parent)
    impl = caching.CacheImpl   # numba's own order of locators
    for cls in impl._locator_classes:
        locator = cls.from_function(fast_step._step_c, str(source))
        if locator is None:
            continue
        try:
            locator.ensure_cache_path()
        except OSError:
            continue
        break
    assert folder == Path(locator.get_cache_path())
    assert not str(folder).startswith(unusable)


def test_a_read_only_installs_stale_caches_in_numbas_user_wide_folder_are_cleared(tmp_path,
                                                                                    monkeypatch):
    """A read-only install: numba cannot write __pycache__ next to the sources and caches in
    its user-wide folder (~/.cache/numba); drop_stale_caches clears stale caches there too,
    after a change of the sources only."""
    from numba.core import caching, config

    from planarsim import compiled
    from planarsim.compile import caches
    monkeypatch.setattr(config, "CACHE_DIR", "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "user_cache"))
    monkeypatch.setattr(caches, "_in_tree_writable", lambda folder: False)
    pkg = tmp_path / "ropkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    source = pkg / "a.py"
    source.write_text("def f(x):\n    return x\n")
    namespace = {}
    exec(compile(source.read_text(), str(source), "exec"), namespace)
    numbas = Path(caching.UserWideCacheLocator(namespace["f"], str(source)).get_cache_path())
    assert caches.cache_folder(pkg) == numbas
    compiled.drop_stale_caches(pkg)
    stale = numbas / "a.f-1.py311.nbi"
    stale.write_text("machine code of the sources as they were")
    compiled.drop_stale_caches(pkg)            # the same sources: kept
    assert stale.exists()
    source.write_text("def f(x):\n    return x + 1\n")
    compiled.drop_stale_caches(pkg)            # changed: cleared
    assert not stale.exists()
