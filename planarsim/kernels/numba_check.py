"""The numba internals planarsim's compiled layer builds on, checked when it is imported.

Beyond numba's documented extension API (numba.extending), kernels/_jit.py lowers kernels into
its own code library (numba.core.codegen, numba.core.compiler), and kernels/refs.py and
kernels/link.py build arrays and calls in LLVM IR (numba.core.cgutils, numba.np.arrayobj).
A numba release that renames or drops one of them fails here, on import, with an error that
names the numba version and each changed internal, instead of an AttributeError deep inside
the first compile. Checked with numba 0.59 to 0.68; pyproject.toml pins numba below 0.69.
"""
import importlib
import inspect

import numba

CHECKED = "0.59-0.68"

# module: attributes (dotted below a class) of every internal used
NEEDED = {
    "numba.core.codegen": "JITCodeLibrary.add_ir_module JITCodeLibrary.finalize "
                          "JITCodeLibrary.get_pointer_to_function JITCodeLibrary.codegen "
                          "JITCodeLibrary._raise_if_finalized JITCodeLibrary._get_module_for_linking "
                          "JITCPUCodegen.set_env",
    "numba.core.compiler": "Compiler.compile_extra",
    "numba.core.compiler_lock": "require_global_compiler_lock global_compiler_lock",
    "numba.core.registry": "CPUDispatcher CPUDispatcher.compile CPUDispatcher.enable_caching "
                           "CPUDispatcher.get_call_template",
    "numba.core.imputils": "impl_ret_borrowed",
    "numba.core.typing.templates": "AttributeTemplate",
    "numba.np.arrayobj": "populate_array",
    "numba.core.cgutils": "alloca_once_value get_or_insert_function is_null pack_array "
                          "unpack_tuple voidptr_t",
}
# fields of a code library that KernelCodeLibrary.finalize reads and sets
LIBRARY_FIELDS = ("_linking_libraries", "_final_module", "_finalized", "_codegen")
# keyword arguments of the dispatcher's constructor that _jit passes
DISPATCHER_ARGS = ("py_func", "locals", "targetoptions", "pipeline_class")


class NumbaChanged(ImportError):
    """The installed numba lacks an internal that planarsim's compiled layer uses."""


def _has(module, path):
    try:
        obj = importlib.import_module(module)
        for part in path.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError):
        return False
    return True


def changed_internals():
    """The internals (as 'module.attribute' text) missing from the installed numba."""
    missing = [f"{module}.{path}" for module, paths in NEEDED.items() for path in paths.split()
               if not _has(module, path)]
    try:
        from numba.core.registry import CPUDispatcher, cpu_target
        params = inspect.signature(CPUDispatcher.__init__).parameters
        missing += [f"numba.core.registry.CPUDispatcher(..., {a}=)" for a in DISPATCHER_ARGS
                    if a not in params]
        library = cpu_target.target_context.codegen().create_library("planarsim_check")
        missing += [f"numba.core.codegen.JITCodeLibrary().{f}" for f in LIBRARY_FIELDS
                    if not hasattr(library, f)]
    except Exception as exc:   # any change in how these are made counts as a change
        missing.append(f"numba.core.registry (making a code library: {type(exc).__name__}: {exc})")
    return missing


def check_numba():
    """Raise NumbaChanged naming the numba version and every changed internal, if any."""
    missing = changed_internals()
    if missing:
        raise NumbaChanged(
            f"planarsim's compiled layer does not work with numba {numba.__version__}: it "
            f"builds on numba internals (checked with numba {CHECKED}) and this numba changed "
            + ", ".join(missing) + ". Install a numba below 0.69: pip install 'numba<0.69'")
