"""dolfinx's compiled core, ``dolfinx.cpp``, without dolfinx's Python layer.

The global system is laid out with dolfinx's index maps, sparsity patterns
and block vectors (:mod:`textile.system.layout`), which live in the compiled
module ``dolfinx.cpp``. Importing it the ordinary way runs the package's
``__init__``, which imports the whole Python layer (fem, mesh, io, jit) and
with it UFL, FFCx and basix: about 0.1 s and 20 MB that only a matrix block
uses. :func:`load` loads the compiled module alone, as the package's
``__init__`` would (same dlopen flags, same logging set-up); a matrix block's
effects import the package later, which then finds this module as its
``cpp`` (the same module object: one set of types).
"""
from __future__ import annotations

import importlib.machinery
import importlib.util
import sys

NAME = "dolfinx.cpp"


class _BindCore:
    """Meta-path finder for the dolfinx package, installed once its core is
    loaded alone: the package is then imported as usual, with the core
    already bound as its ``cpp`` attribute (the import system binds only
    the submodules it loads itself). Used once, then removed."""

    @classmethod
    def find_spec(cls, name, path=None, target=None):
        if name != "dolfinx":
            return None
        if cls in sys.meta_path:
            sys.meta_path.remove(cls)
        spec = importlib.machinery.PathFinder.find_spec(name, path)
        if spec is None or spec.loader is None:
            return spec
        execute = spec.loader.exec_module

        def exec_module(module):
            module.cpp = sys.modules[NAME]
            execute(module)

        spec.loader.exec_module = exec_module
        return spec


def load():
    """The module ``dolfinx.cpp``, loaded without the dolfinx package if the
    package is not imported yet."""
    if NAME in sys.modules:
        return sys.modules[NAME]
    package = importlib.util.find_spec("dolfinx") if "dolfinx" not in sys.modules else None
    spec = None
    if package is not None and package.submodule_search_locations:
        spec = importlib.machinery.PathFinder.find_spec(NAME, package.submodule_search_locations)
    if spec is None or not isinstance(spec.loader, importlib.machinery.ExtensionFileLoader):
        from dolfinx import cpp   # not the usual layout: the ordinary import

        return cpp
    if "linux" in sys.platform:   # as dolfinx/__init__.py does (OpenMPI), and keeps
        sys.setdlopenflags(2 | 256)   # RTLD_NOW | RTLD_GLOBAL
    module = importlib.util.module_from_spec(spec)
    sys.modules[NAME] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[NAME]
        raise
    module.common.init_logging(sys.argv)   # as dolfinx/__init__.py does
    sys.meta_path.insert(0, _BindCore)
    return module
