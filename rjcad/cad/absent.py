"""Packages CadQuery imports but a joint's build never uses, replaced by placeholders in the CAD process
(``rjcad.cad.process``), whose start-up is ``rjcad joint``'s longest wait.

``import cadquery`` loads VTK's modules (its shapes' VTK conversions, its VTK and VRML exporters, OCP's VTK
bridge), ezdxf (the DXF exporter) and CasADi (the assembly solver) at import time: 0.41 s of its 1.98 s here
(1.98 → 1.56 s, median of 11 paired runs, with ``import vtk`` already deferred by ``rjcad.cad``). Building,
meshing, measuring and writing STEP touch none of them. With ``install()``, importing any of ``PACKAGES``
(or a submodule) gives an empty module whose attributes are placeholders: classes that can be named, used
in annotations and default values, subclassed, and whose attributes are more placeholders, but that raise
``AbsentError`` when called. So a build that reached for one fails loudly (the CAD process then hands the
build back to the program, which builds it with the real packages: ``rjcad.cad.process``), never silently.

Only for a process of its own: the placeholders stay in ``sys.modules`` once installed.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import sys
import types

#: Set to 0 to load every package in the CAD process.
ENV = "RJCAD_CAD_ABSENT"

#: Packages (and modules of OCP) left out of the CAD process: VTK and OCP's VTK bridge, ezdxf, CasADi.
PACKAGES = ("vtk", "vtkmodules", "OCP.IVtk", "OCP.IVtkOCC", "OCP.IVtkTools", "OCP.IVtkVTK", "ezdxf", "casadi")


class AbsentError(RuntimeError):
    """A placeholder for a package left out of this process was called."""


class _PlaceholderType(type):
    """The type of placeholders: an attribute of a placeholder is a placeholder; calling one raises."""

    def __getattr__(cls, name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        return _placeholder(f"{cls.__qualname__}.{name}", cls.__module__)

    def __call__(cls, *args, **kwargs):
        raise AbsentError(f"{cls.__module__}.{cls.__qualname__} was called, but this process leaves "
                          f"{cls.__module__} out (rjcad.cad.absent)")


def _placeholder(qualname: str, module: str) -> type:
    return _PlaceholderType(qualname.rsplit(".", 1)[-1], (), {"__qualname__": qualname, "__module__": module})


class _AbsentModule(types.ModuleType):
    """A package left out: every attribute is a placeholder (submodules are imported as absent modules too)."""

    def __getattr__(self, name: str):
        if name.startswith("__"):
            raise AttributeError(name)
        value = _placeholder(name, self.__name__)
        setattr(self, name, value)
        return value


def is_absent(name: str) -> bool:
    """True if the module ``name`` is one of ``PACKAGES`` or inside one."""
    return any(name == p or name.startswith(p + ".") for p in PACKAGES)


class _Finder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Finds ``PACKAGES`` before the real finders do, as empty packages."""

    def find_spec(self, fullname, path, target=None):
        if is_absent(fullname):
            return importlib.machinery.ModuleSpec(fullname, self, is_package=True)
        return None

    def create_module(self, spec):
        module = _AbsentModule(spec.name)
        module.__path__ = []
        return module

    def exec_module(self, module) -> None:
        pass


def install() -> bool:
    """Leave ``PACKAGES`` out of this process from now on (again: nothing more to do). False (nothing done) if
    one is already loaded (VTK's umbrella module deferred by ``rjcad.cad.defer_vtk_umbrella`` and not yet run
    does not count: it is replaced)."""
    from rjcad.cad import _Deferred

    present = [name for name in sys.modules if is_absent(name)]
    if any(not isinstance(sys.modules[name], (_Deferred, _AbsentModule)) for name in present):
        return False
    for name in present:
        if isinstance(sys.modules[name], _Deferred):
            module = sys.modules[name] = _AbsentModule(name)
            module.__path__ = []
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.insert(0, _Finder())
    return True


def installed() -> bool:
    """True if ``install()`` took effect in this process."""
    return any(isinstance(f, _Finder) for f in sys.meta_path)
