"""Analytic mode: every design point through the vectorised spring optimiser, grouped by material, printer, end.

The optimiser's physics here is the rod model's table surrogate only: rows say ``verified = False``
(build mode, and ``rjcad spring``, wind every design with the full rod model: ``verified = True``).
"""

from __future__ import annotations

import math

import numpy as np

from rjcad.design.params import RANGES
from rjcad.errors import RjcadError
from rjcad.life.constraint import predict_cycles
from rjcad.materials import get_material, get_printer
from rjcad.spring.design import SpringRequirement
from rjcad.spring.optimise import CONSTRAINTS, optimise_arrays, row_message
from rjcad.sweep.spec import point_id
from rjcad.validate import in_range


def _life_columns(rows: list[dict]) -> None:
    """Predicted life (median and 90 % interval, backlash 0.25 mm) of the feasible rows (rjcad.life)."""
    ok = [r for r in rows if r.get("feasible")]
    if not ok:
        return
    amp = np.array([r["stress_amplitude_mpa"] for r in ok])
    med, lo, hi = predict_cycles(amp, np.array([r["thickness_mm"] for r in ok]), 0.25)
    for r, a, b, c in zip(ok, med, lo, hi):
        r["predicted_cycles"], r["predicted_cycles_lo"], r["predicted_cycles_hi"] = float(a), float(b), float(c)


def analytic_rows(points: list[dict]) -> list[dict]:
    """Spring design for every point, vectorised per (material, printer, end) group.

    A point whose inputs are invalid becomes a failed row with its error.
    """
    rows: list[dict | None] = [None] * len(points)
    groups: dict[tuple, list[int]] = {}
    for i, pt in enumerate(points):
        try:
            # validates every input with the same rules as `rjcad spring`
            SpringRequirement(
                float(pt["stiffness_nmm_per_rad"]),
                math.radians(float(pt["rotation_deg"])),
                math.radians(float(pt["preload_deg"])),
                pt["material"],
                pt["printer"],
                float(pt["safety_factor"]),
                pt["end"],
            )
            # the joint's own inputs, as the builder checks them (its link's lower bound needs the CAD layout)
            in_range("clearance_mm", pt["clearance_mm"], *RANGES["clearance"][:2], unit="mm")
            get_printer(pt["printer"]).check_gap("clearance_mm", pt["clearance_mm"])
            in_range("link_length_mm", pt["link_length_mm"], 0.0, RANGES["link_length"][1], lo_open=True, unit="mm")
        except RjcadError as e:
            rows[i] = {**pt, "id": point_id(pt), "status": "failed", "feasible": False, "error": str(e)}
            continue
        key = (get_material(pt["material"]).ref, get_printer(pt["printer"]).ref, pt["end"])
        groups.setdefault(key, []).append(i)
    for (mat, prn, end), idx in groups.items():
        material, printer = get_material(mat), get_printer(prn)
        K = np.array([float(points[i]["stiffness_nmm_per_rad"]) for i in idx])
        rot = np.radians([float(points[i]["rotation_deg"]) for i in idx])
        pre = np.radians([float(points[i]["preload_deg"]) for i in idx])
        sf = np.array([float(points[i]["safety_factor"]) for i in idx])
        allow = material.yield_strength_mpa / sf
        res = optimise_arrays(
            K / 2, rot + pre, material=material, printer=printer, allowed_stress=allow, end=end, rotation=rot
        )
        Ks = res["spring_stiffness"]
        cols = {
            "width_mm": res["width"],
            "thickness_mm": res["thickness"],
            "length_mm": res["length"],
            "inner_radius_mm": res["inner_radius"],
            "pitch_mm": res["pitch"],
            "turns": res["turns"],
            "outer_radius_mm": res["outer_radius"],
            "spring_stiffness_nmm_per_rad": Ks,
            "joint_stiffness_nmm_per_rad": 2 * Ks,
            "max_stress_mpa": res["max_stress"],
            "allowed_stress_mpa": allow,
            "min_coil_gap_mm": res["min_coil_gap"],
            "stress_amplitude_mpa": res["stress_amplitude"],
        }
        for k, i in enumerate(idx):
            row = {**points[i], "id": point_id(points[i]), "material": mat, "printer": prn, "verified": False}
            if res["feasible"][k]:
                row.update({c: float(v[k]) for c, v in cols.items()})
                row.update(
                    status="ok",
                    feasible=True,
                    binding="",
                    error="",
                    stress_margin=float(allow[k] / res["max_stress"][k]),
                )
            else:
                name = CONSTRAINTS[int(res["binding"][k])]
                row.update(status="infeasible", feasible=False, binding=name, error=row_message(res, k, 0.25, end))
            rows[i] = row
    out = [r for r in rows if r is not None]
    _life_columns(out)
    return out
