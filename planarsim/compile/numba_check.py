"""The numba internals planarsim's fast mode builds on, checked when planarsim is imported.

Beyond numba's documented extension API (numba.extending), compile/fast.py lowers kernels into
its own code library (numba.core.codegen, numba.core.compiler) and compiles with flags of its
own (flags.py: numba's function compilers subclassed), and compile/refs.py and
planarsim/link/fast_step.py build arrays and calls in LLVM IR (numba.core.cgutils).
A numba release that renames or drops one of them is found here, before anything compiles,
and planarsim runs on plain numba instead (compile/mode.py), warning with the numba version
and each changed internal. Checked with numba 0.59 to 0.68.
"""
import importlib
import inspect

CHECKED = "0.59-0.68"

# module: attributes (dotted below a class) of every internal used: the fast mode's code
# library and pipeline (fast.py, fast_step.py)
NEEDED = {
    "numba.core.codegen": "JITCodeLibrary.add_ir_module JITCodeLibrary.finalize "
                          "JITCodeLibrary.get_pointer_to_function JITCodeLibrary.codegen "
                          "JITCodeLibrary._raise_if_finalized JITCodeLibrary._get_module_for_linking "
                          "JITCPUCodegen.set_env",
    "numba.core.caching": "FunctionCache IndexDataCacheFile",
    "numba.core.ccallback": "CFunc CFunc.compile CFunc.enable_caching CFunc._targetdescr "
                            "_CFuncCompiler._customize_flags",  # parts.py, flags.py
    "numba.core.dispatcher": "_FunctionCompiler _FunctionCompiler._customize_flags",  # flags.py
    "numba.core.compiler_lock": "require_global_compiler_lock global_compiler_lock",
    "numba.core.registry": "CPUDispatcher CPUDispatcher.compile CPUDispatcher.enable_caching "
                           "CPUDispatcher.get_call_template",
    "numba.core.compiler": "Compiler.compile_extra Flags",
    "numba.core.targetconfig": "TargetConfig.options TargetConfig.__slots__",   # flags.py
}
# numba's low-level extension API as refs.py uses it (numba.extending and the helpers its
# documentation's examples use): model, state and workspace as one pointer each, in both the
# fast and the plain mode
NEEDED_TABLES = {
    "numba.extending": "NativeValue infer_getattr intrinsic lower_getattr_generic models "
                       "register_model typeof_impl unbox",
    "numba.core.imputils": "impl_ret_borrowed",
    "numba.core.typing.templates": "AttributeTemplate",
    "numba.core.cgutils": "alloca_once_value get_or_insert_function is_null pack_array "
                          "unpack_tuple voidptr_t",
}
# the fields of numba's array struct (numba.core.datamodel's ArrayModel) that refs._c_array
# fills by name
ARRAY_FIELDS = ("meminfo", "parent", "nitems", "itemsize", "data", "shape", "strides")
# fields of a code library that KernelCodeLibrary.finalize reads and sets
LIBRARY_FIELDS = ("_linking_libraries", "_final_module", "_finalized", "_codegen")
# fields of a dispatcher's (and a C function's) compiler that flags.quick_compiler reads
COMPILER_FIELDS = ("py_func", "targetdescr", "targetoptions", "locals", "pipeline_class")
# keyword arguments of the dispatcher's constructor that fast.py passes
DISPATCHER_ARGS = ("py_func", "locals", "targetoptions", "pipeline_class")


def _probe():
    return 0


def _has(module, path):
    try:
        obj = importlib.import_module(module)
        for part in path.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        return False
    return True


def _missing(needed):
    return [f"{module}.{path}" for module, paths in needed.items() for path in paths.split()
            if not _has(module, path)]


def changed_tables():
    """The extension API pieces refs.py uses (as 'module.attribute') missing from numba,
    and the fields of numba's array struct that refs._c_array fills."""
    missing = _missing(NEEDED_TABLES)
    try:
        from numba.core import types
        from numba.core.registry import cpu_target
        model = cpu_target.target_context.data_model_manager[types.Array(types.float64, 2, "C")]
        for name in ARRAY_FIELDS:
            model.get_field_position(name)
    except Exception as exc:   # a renamed field, or a changed way to reach the model
        missing.append(f"numba.core.datamodel ArrayModel fields ({type(exc).__name__}: {exc})")
    return missing


def changed_internals():
    """The internals of the fast mode (as 'module.attribute' text) missing from numba."""
    missing = _missing(NEEDED) + changed_tables()
    try:
        from numba.core import ccallback as numba_ccallback
        from numba.core import types
        from numba.core.registry import CPUDispatcher, cpu_target
        params = inspect.signature(CPUDispatcher.__init__).parameters
        missing += [f"numba.core.registry.CPUDispatcher(..., {a}=)" for a in DISPATCHER_ARGS
                    if a not in params]
        library = cpu_target.target_context.codegen().create_library("planarsim_check")
        missing += [f"numba.core.codegen.JITCodeLibrary().{f}" for f in LIBRARY_FIELDS
                    if not hasattr(library, f)]
        from numba.core.targetconfig import TargetConfig
        if "_values" not in TargetConfig.__slots__:   # flags.py compares the set options
            missing.append("numba.core.targetconfig.TargetConfig._values")
        for owner in (CPUDispatcher(py_func=_probe, locals={}, targetoptions={}),
                      numba_ccallback.CFunc(_probe, ((), types.int64), {}, {})):
            compiler = getattr(owner, "_compiler", None)   # flags.py replaces each one's own
            if compiler is None or not all(hasattr(compiler, a) for a in COMPILER_FIELDS):
                missing.append(f"{type(owner).__name__}()._compiler ({', '.join(COMPILER_FIELDS)})")
    except Exception as exc:   # any change in how these are made counts as a change
        missing.append(f"numba.core.registry (making a code library: {type(exc).__name__}: {exc})")
    return missing
