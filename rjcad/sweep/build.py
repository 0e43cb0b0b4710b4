"""Build mode: one task per design point, the joint built (OpenCASCADE) and checked (process pool or Dask)."""

from __future__ import annotations

import math
import time
from pathlib import Path

from rjcad.errors import RjcadError
from rjcad.io.config import write_atomic
from rjcad.io.outputs import OutputError
from rjcad.sweep.spec import DESIGN_KEYS, point_id


def build_task(point: dict, mesh_dir: str | None = None) -> dict:
    """Build and check the joint of one design point; never raises (a failure is a row)."""
    row = {**point, "id": point_id(point)}
    t0 = time.perf_counter()
    try:
        from rjcad.cad.build import build, render_files
        from rjcad.design.params import JointParams

        p = JointParams(
            stiffness=float(point["stiffness_nmm_per_rad"]),
            rotation=math.radians(float(point["rotation_deg"])),
            preload=math.radians(float(point["preload_deg"])),
            material=point["material"],
            printer=point["printer"],
            safety_factor=float(point["safety_factor"]),
            end=point["end"],
            clearance=float(point["clearance_mm"]),
            link_length=float(point["link_length_mm"]),
        )
        b = build(p)
        row["build_s"] = time.perf_counter() - t0
        row.update({k: b.manifest["spring"][k] for k in DESIGN_KEYS})
        row["verified"] = True  # the builder's spring went through design_spring: wound by the full rod model
        row["triangles"] = b.manifest["mesh"]["triangles"]
        row["measured_min_gap_mm"] = b.manifest["measured_min_gap_mm"]
        row.update(_check_joint(b))
        if mesh_dir:
            files = render_files(b, "joint", png=False)
            write_atomic(Path(mesh_dir) / f"{row['id']}.stl", files["joint.stl"])
        row.update(status="ok" if row["checks_passed"] else "check_failed", feasible=True, error="")
    except OutputError:
        raise  # a mesh that cannot be written stops the sweep (a full disk): it is not the design's fault
    except RjcadError as e:
        row.update(status="infeasible", feasible=False, error=str(e), build_s=time.perf_counter() - t0)
    except Exception as e:  # a design that raises is a failed row, never a crashed sweep
        row.update(status="failed", feasible=False, error=f"{type(e).__name__}: {e}", build_s=time.perf_counter() - t0)
    return row


def _check_joint(b) -> dict:
    """Run the print-readiness checks (rjcad.check) on a built joint."""
    from rjcad.check import run_checks

    d = run_checks(
        list(b.meshes.values()),
        manifest=b.manifest,
        clearance=b.manifest["clearance_mm"],
        printer=b.manifest["printer"],
    ).to_dict()
    failed = [c["name"] for c in d["checks"] if c["passed"] is False]
    return {"checks_passed": bool(d["passed"]), "checks_failed": ";".join(failed)}
