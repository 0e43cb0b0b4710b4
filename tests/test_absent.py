"""What the CAD process leaves out (``rjcad.cad.absent``) and imports without the garbage collector
(``rjcad.imports``). Each check runs in a fresh interpreter: both change the process they run in for good."""

from __future__ import annotations

import json
import subprocess
import sys

from conftest import ROOT


def _python(code: str) -> dict:
    """Run ``code`` in a new interpreter; the JSON object it prints last."""
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


PLACEHOLDERS = """
import json, sys, typing
import rjcad.cad  # defers VTK's umbrella module, as the CAD process inherits it
from rjcad.cad import absent
deferred = type(sys.modules["vtk"]).__name__
installed = absent.install()
import vtk
from vtkmodules.vtkCommonDataModel import vtkPolyData
from ezdxf import units
import casadi as ca
from OCP.IVtkOCC import IVtkOCC_Shape

class Mine(vtkPolyData):  # a subclass can be defined
    pass

def f(x: typing.Optional[vtkPolyData] = units.MM): return x  # annotations and defaults

calls = {}
for name, fn in [("class", vtkPolyData), ("attribute", units.MM), ("subclass", Mine), ("casadi", ca.MX.sym),
                 ("vtk", vtk.vtkActor), ("ocp", IVtkOCC_Shape)]:
    try:
        fn()
        calls[name] = "no error"
    except absent.AbsentError as e:
        calls[name] = str(e)
import numpy  # a package not left out loads as usual
print(json.dumps({"deferred": deferred, "installed": installed, "again": absent.install(),
                  "vtk": type(sys.modules["vtk"]).__name__, "ezdxf_file": getattr(sys.modules["ezdxf"], "__file__", None),
                  "f": f.__defaults__[0].__qualname__, "calls": calls, "numpy": numpy.__name__,
                  "is_absent": [absent.is_absent(n) for n in ("vtkmodules.util", "vtkx", "OCP.IVtkOCC", "OCP.gp")]}))
"""


def test_left_out_packages_import_as_placeholders_that_raise_when_called():
    got = _python(PLACEHOLDERS)
    assert got["deferred"] == "_Deferred"  # rjcad.cad's deferred `vtk` (not yet run) does not count as loaded
    assert got["installed"] is True and got["again"] is True
    assert got["vtk"] == "_AbsentModule" and got["ezdxf_file"] is None  # nothing of the real packages ran
    assert got["f"] == "units.MM"
    assert got["calls"]["class"] == ("vtkmodules.vtkCommonDataModel.vtkPolyData was called, but this process "
                                     "leaves vtkmodules.vtkCommonDataModel out (rjcad.cad.absent)")
    assert all(text.endswith("out (rjcad.cad.absent)") for text in got["calls"].values()), got["calls"]
    assert "units.MM was called" in got["calls"]["attribute"] and "Mine was called" in got["calls"]["subclass"]
    assert "MX.sym was called" in got["calls"]["casadi"]
    assert got["numpy"] == "numpy"
    assert got["is_absent"] == [True, False, True, False]


def test_nothing_is_left_out_once_a_real_package_is_loaded():
    got = _python("""
import json, sys
import vtkmodules.vtkCommonCore
from rjcad.cad import absent
print(json.dumps({"installed": absent.install(), "finder": absent.installed(),
                  "vtkmodules": type(sys.modules["vtkmodules"]).__name__}))
""")
    assert got == {"installed": False, "finder": False, "vtkmodules": "module"}


def test_load_pauses_the_collector_for_a_first_import_only_and_restores_it():
    got = _python("""
import gc, json, sys
from rjcad import imports
seen = []
gc.callbacks.append(lambda phase, info: seen.append(phase))
frozen0 = gc.get_freeze_count()
m = imports.load("trimesh")  # a large package: the collector would run during its import
first = {"collections": len(seen), "frozen": gc.get_freeze_count() > frozen0, "enabled": gc.isenabled()}
frozen1 = gc.get_freeze_count()
again = imports.load("trimesh") is m and gc.get_freeze_count() == frozen1  # loaded: nothing paused or frozen
gc.disable()
with imports.collector_paused():
    pass
off_stays_off = not gc.isenabled()
print(json.dumps({"first": first, "again": again, "off_stays_off": off_stays_off}))
""")
    assert got == {"first": {"collections": 0, "frozen": True, "enabled": True}, "again": True,
                   "off_stays_off": True}
