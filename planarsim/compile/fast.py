"""The fast mode's compiler (compile/mode.py): numba's dispatchers with planarsim's own code
library, and the code layout of planarsim's machine code.

cache=True: compiled once per machine, loaded from disk afterwards. Kernels themselves are not
cached: they are IR linked into their compiled callers (the step, rollouts), which are.
fastmath=False: fastmath lets LLVM assume no NaNs and would remove the isfinite guards.
_nrt=False: kernels never allocate; without the runtime's reference counting, passing the
model/state/workspace NamedTuples (dozens of arrays) between stages costs nothing, where
with it every call increments and decrements every array (about 1 us per call).

The kernels' code library and pipeline use numba internals (numba_check.py checks them on
import; without them planarsim runs on plain numba). Measured with numba 0.68.1: plain `njit`
kernels with numba's own library (each kernel optimised and emitted as machine code at every
nesting level) took the cold start to a walker's first step from about 36 s to 59-68 s on one
machine (same steps/s, same bits).
"""
import contextlib
import os

import llvmlite.binding as llvm
from numba import types
from numba.core import compiler
from numba.core.caching import FunctionCache, IndexDataCacheFile
from numba.core.codegen import JITCodeLibrary
from numba.core.compiler_lock import global_compiler_lock, require_global_compiler_lock
from numba.core.registry import CPUDispatcher

from .flags import quick_compiler

_OPTIONS = dict(cache=True, fastmath=False, nogil=True, error_model="numpy", _nrt=False)


# LLVM's code layout while planarsim's machine code is emitted: every function and every block
# not entered by falling through from the one before starts on a 64-byte line (padding only:
# the same instructions, the same numbers). Without it, where a hot loop's blocks fall
# relative to the 64-byte lines the CPU fetches and caches decoded code by depends on the size
# of all the code before it, so an edit anywhere in the step moved small scenes by 5-10%
# either way (with it, by 2-7%). Measured with it (numba 0.68.1, AMD EPYC): 2-12% more
# steps/s on the bench scenes and walkers, none slower. LLVM keeps such options
# process-wide, so they are set only while planarsim compiles (under numba's compiler lock)
# and then set to LLVM's defaults (LLVM_DEFAULTS): numba code compiled outside planarsim's
# compiles is laid out as without planarsim (a plain numba function compiled as part of a
# planarsim caller gets the layout; a user's own setting of these options is not kept). numba's
# cache does not record the options: code cached before them runs unaligned (only slower).
CODE_LAYOUT = ("-align-all-functions=6", "-align-all-nofallthru-blocks=6")
# GVN (redundant load elimination) scans at most this many instructions back within a block
# for what a load depends on (LLVM's default 100). On the step's few very long blocks its
# scans were the largest part of O3: 20 takes about 2 s off the step's first compile, with
# steps/s the same within the noise on the bench scenes and walkers (measured, numba 0.68.1).
MEMDEP_SCAN = ("-memdep-block-scan-limit=20",)
# set while planarsim compiles, and LLVM's defaults set back afterwards
PLANARSIM_LLVM = CODE_LAYOUT + MEMDEP_SCAN
LLVM_DEFAULTS = ("-align-all-functions=0", "-align-all-nofallthru-blocks=0",
                 "-memdep-block-scan-limit=100")
_LAYOUT_DEPTH = [0]


@contextlib.contextmanager
def code_layout():
    """Compile planarsim's machine code inside this block (reentrant; see CODE_LAYOUT and
    MEMDEP_SCAN)."""
    with global_compiler_lock:
        if _LAYOUT_DEPTH[0] == 0:
            for option in PLANARSIM_LLVM:
                llvm.set_option("planarsim", option)
        _LAYOUT_DEPTH[0] += 1
        try:
            yield
        finally:
            _LAYOUT_DEPTH[0] -= 1
            if _LAYOUT_DEPTH[0] == 0:
                for option in LLVM_DEFAULTS:
                    llvm.set_option("planarsim", option)


# what runs before a `jit` function's machine code is compiled or loaded from the cache: the
# layer above publishes there the symbols that code may name (planarsim/link/fast_step.py:
# the compiled step's)
_BEFORE_COMPILE = []


def before_compile(hook):
    """Run hook() before any `jit` function compiles or loads its machine code, and before a
    compiled caller of a part is typed (compile/parts.py); once registered, it runs each time
    (returns hook)."""
    if hook not in _BEFORE_COMPILE:
        _BEFORE_COMPILE.append(hook)
    return hook


def prepare_compile():
    """Run the before_compile hooks."""
    for hook in _BEFORE_COMPILE:
        hook()


class CallerDispatcher(CPUDispatcher):
    """Dispatcher of a `jit` function. Its machine code may call code by a symbol that LLVM
    resolves when the code is compiled or loaded from the cache (the compiled step's); so
    before either, the before_compile hooks publish those symbols. Importing a module of
    compiled code therefore compiles nothing: a command that only lists walkers or
    parameters never waits for the step. Compiles with planarsim's flags (flags.py)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._compiler = quick_compiler(self._compiler)

    def compile(self, sig):
        prepare_compile()
        with code_layout():
            return super().compile(sig)


class FastFunctionCache(FunctionCache):
    """numba's disk cache of a `jit` function, in files of its own ("<name>-fast.nbi"). On
    plain numba (PLANARSIM_PLAIN_NUMBA=1) the same function has the same cache key, but its
    code inlines the step where the fast mode's calls the step's published symbol: a process
    loading the other mode's code would call an address never published (a crash, seen with
    both modes run at once on one cache). A switch of mode clears the caches anyway
    (caches.py); this keeps processes of the two modes apart while they run side by side."""

    def __init__(self, py_func):
        super().__init__(py_func)
        try:
            base, stamp = self._impl.filename_base, self._impl.locator.get_source_stamp()
        except AttributeError:     # a numba that moved them: its own files (both modes share)
            return
        self._cache_file = IndexDataCacheFile(cache_path=self._cache_path,
                                              filename_base=base + "-fast", source_stamp=stamp)


def _caller_decorator(**extra):
    options = dict(_OPTIONS, nopython=True, boundscheck=None, **extra)
    cache = options.pop("cache")

    def decorate(fn):
        dispatcher = CallerDispatcher(py_func=fn, locals={}, targetoptions=dict(options))
        if cache:
            dispatcher._cache = FastFunctionCache(fn)
        return dispatcher
    return decorate


# for numba.cfunc (the step's C entry, cached by its own argument): a C function holds no GIL
KERNEL_OPTIONS = {k: v for k, v in _OPTIONS.items() if k not in ("cache", "nogil")}
# PLANARSIM_KERNEL_CALLS=1 keeps kernels as calls, so that a profiler sees each stage
# (benchmarks/profile_kernels.py sets it, with a cache of its own)
KERNEL_CALLS = os.environ.get("PLANARSIM_KERNEL_CALLS") == "1"
# kernel: a function called only from other compiled code. numba then builds neither its Python
# wrapper (which unboxes every array of the model, state and workspace: thousands of lines of
# LLVM IR per function) nor its C wrapper; this halves the first-ever compile of the step.
# Anything called from Python (rollouts, run_recorded, step_entry, terrain queries) keeps `jit`.
class KernelDispatcher(CPUDispatcher):
    """Dispatcher of a kernel. Compiled code calls it directly; a call from Python is refused
    with a clear error (numba would jump into the Python wrapper that was never built).
    Compiles with planarsim's flags (flags.py)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._compiler = quick_compiler(self._compiler)

    def __call__(self, *args, **kwargs):
        name = self.py_func.__qualname__
        raise TypeError(f"{self.py_func.__module__}.{name} is a compiled kernel: call it from "
                        "compiled code (a rollout decorated with planarsim.compiled.jit); from "
                        "Python use Simulator.step / steps or planarsim.compiled.step_from_python")

    def get_call_template(self, args, kws):
        """Compile for the arguments' plain types: a constant argument (a row kind, an audit
        rule) would otherwise make one more compilation of the kernel per value."""
        args = tuple(types.unliteral(a) for a in args)
        kws = {k: types.unliteral(v) for k, v in kws.items()}
        return super().get_call_template(args, kws)


class KernelCodeLibrary(JITCodeLibrary):
    """LLVM IR of a kernel, never compiled to machine code on its own.

    numba finalises every function's library: it links in the libraries of its callees,
    optimises the whole (O3) and emits machine code. A kernel is only ever linked into a
    compiled caller (the step, a rollout), where all of it is optimised and emitted again:
    for the step's nested stages that was each leaf's code optimised once per level it is
    nested in and emitted as machine code at every level, most of a first-ever start-up's
    LLVM time. Here finalising only links the callees' IR in (as linkonce_odr, so that
    copies reaching a caller along several paths merge); the caller optimises and emits
    everything once."""

    noinline = False   # mark the kernel's function noinline (kernel(inline="never"))

    def add_ir_module(self, ir_module):
        if self.noinline:
            for fn in ir_module.functions:
                if not fn.is_declaration and "alwaysinline" not in fn.attributes:
                    fn.attributes.add("noinline")
        super().add_ir_module(ir_module)

    def get_pointer_to_function(self, name):
        return 0   # no entry of its own: compiled code calls a kernel, Python never does

    @property
    def codegen(self):
        return _KernelCodegen(self._codegen)

    def finalize(self):
        require_global_compiler_lock()
        self._raise_if_finalized()
        seen = set()
        for library in self._linking_libraries:
            if library not in seen:
                seen.add(library)
                self._final_module.link_in(library._get_module_for_linking(), preserve=True)
        self._final_module.verify()
        self._finalized = True


class _KernelCodegen:
    """The codegen as a kernel's library shows it: numba's lowering stores the address of the
    function's environment in the execution engine, where a kernel is never added. Kernels
    use no environment (nopython, no Python objects), so that store is skipped. Hence a kernel
    must not print, raise or use objmode: those read the environment, which a freshly compiled
    caller would then lack."""

    def __init__(self, codegen):
        self._codegen = codegen

    def set_env(self, env_name, env):
        pass

    def __getattr__(self, name):
        return getattr(self._codegen, name)


class KernelCompiler(compiler.Compiler):
    """numba's pipeline, lowering a kernel into a KernelCodeLibrary."""
    noinline = False

    def compile_extra(self, func):
        if self.state.library is None:
            codegen = self.state.targetctx.codegen()
            self.state.library = KernelCodeLibrary(codegen, func.__qualname__)
            self.state.library.noinline = self.noinline
        return super().compile_extra(func)


class KernelCallCompiler(KernelCompiler):
    """As KernelCompiler, for a kernel that stays a call (kernel(inline="never"))."""
    noinline = True


def _kernel_decorator(pipeline_class=KernelCompiler, **extra):
    options = dict(_OPTIONS, nopython=True, boundscheck=None, no_cpython_wrapper=True,
                   no_cfunc_wrapper=True, **extra)
    options.pop("cache")

    def decorate(fn):
        return KernelDispatcher(py_func=fn, locals={}, targetoptions=dict(options),
                                pipeline_class=pipeline_class)
    return decorate


def jit(inline=None):
    """The decorator of a `jit` function (compile/decorators.py): inline None (LLVM decides),
    "always" (numba inlines it into its compiled callers) or "force" (LLVM always inlines it)."""
    if inline == "always":
        return _caller_decorator(inline="always")
    if inline == "force":
        return _caller_decorator(forceinline=True)
    return _caller_decorator()


def kernel(inline="force"):
    """The decorator of a kernel (compile/decorators.py): inline "force" (LLVM inlines it into
    its compiled callers; a call under PLANARSIM_KERNEL_CALLS=1), "always" (numba inlines it
    before LLVM sees it; a call too under PLANARSIM_KERNEL_CALLS=1) or "never" (one copy of
    its code that callers call)."""
    if inline == "always" and not KERNEL_CALLS:
        return _kernel_decorator(inline="always")
    if inline == "never":
        return _kernel_decorator(pipeline_class=KernelCallCompiler, forceinline=False)
    return _kernel_decorator(forceinline=not KERNEL_CALLS)
