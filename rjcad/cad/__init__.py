"""CadQuery builders: spiral springs, the joint module, the finger, and exports.

Importing this package defers VTK's umbrella module (see :func:`defer_vtk_umbrella`) before any builder
imports CadQuery.
"""

from __future__ import annotations

import importlib.util
import sys
import types


class _Deferred(types.ModuleType):
    """A module executed on the first read of a name it does not hold yet (``__spec__`` and the like it holds:
    the import system reads those, and a second ``import vtk`` must not load it)."""

    def __getattr__(self, name: str):
        spec = self.__spec__
        real = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = real
        try:
            spec.loader.exec_module(real)
        except BaseException:
            sys.modules[spec.name] = self
            raise
        self.__dict__.update(real.__dict__)
        return getattr(real, name)


def defer_vtk_umbrella() -> bool:
    """Register ``vtk`` as a module executed on first use, unless it is already imported; True if deferred.

    OCP's ``IVtkOCC`` package runs ``import vtk`` only to make sure VTK is there; that module loads all of
    VTK's ~150 wrapped libraries (1.3 s of the 5 s that ``rjcad joint`` spent importing). CadQuery itself
    imports the three ``vtkmodules`` it uses, and the preview imports its own. ``vtk`` still imports; it
    executes in full on the first name anyone reads from it, so code that uses ``vtk.<name>`` sees no
    difference. (The standard ``importlib.util.LazyLoader`` cannot do this: a second ``import vtk`` reads
    ``__spec__`` and so executes it.)
    """
    if "vtk" in sys.modules:
        return False
    spec = importlib.util.find_spec("vtk")
    if spec is None or spec.loader is None:
        return False
    stub = _Deferred("vtk")
    stub.__spec__, stub.__loader__, stub.__file__ = spec, spec.loader, spec.origin
    sys.modules["vtk"] = stub
    return True


defer_vtk_umbrella()
