"""Design-parameter sweeps: analytic (vectorised spring optimiser) or build mode (CAD + checks).

A sweep file (TOML)::

    [sweep]
    mode = "grid"            # or "lhs" (Latin hypercube)
    samples = 200            # lhs only
    seed = 1                 # lhs only

    [fixed]
    preload_deg = 90

    [params.stiffness_nmm_per_rad]
    range = [2, 12]          # grid: with steps = N; lhs: continuous
    steps = 6
    [params.material]
    values = ["absplus-p430", "pla", "petg"]

Execution: a local process pool, or a Dask distributed cluster given its
scheduler address; the tasks are the same plain functions either way.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from rjcad import spring as sp
from rjcad.spring.optimise import CONSTRAINTS, infeasible_message, optimise_arrays
from rjcad.config import load_toml, write_atomic
from rjcad.errors import ParameterError, RjcadError
from rjcad.materials import get_material, get_printer

#: Sweepable inputs: name → (type, default). Angles in degrees (the column names say so).
INPUTS: dict[str, tuple[type, Any]] = {
    "stiffness_nmm_per_rad": (float, 5.2),
    "rotation_deg": (float, 90.0),
    "preload_deg": (float, 90.0),
    "material": (str, "absplus-p430"),
    "printer": (str, "generic-0.4"),
    "safety_factor": (float, 1.5),
    "end": (str, sp.DEFAULT_END),
    "clearance_mm": (float, 0.25),
    "link_length_mm": (float, 40.0),
}
DESIGN_KEYS = ("width_mm", "thickness_mm", "length_mm", "inner_radius_mm", "pitch_mm", "turns",
               "outer_radius_mm", "spring_stiffness_nmm_per_rad", "joint_stiffness_nmm_per_rad",
               "max_stress_mpa", "allowed_stress_mpa", "min_coil_gap_mm")


# --------------------------------------------------------------------------
# sweep definition
# --------------------------------------------------------------------------


@dataclass(frozen=True)
class SweepSpec:
    """Parsed sweep: varied parameters, fixed ones, and the sampling plan."""

    params: dict[str, dict]
    fixed: dict[str, Any]
    mode: str = "grid"
    samples: int = 0
    seed: int = 0

    @classmethod
    def from_toml(cls, path: str | Path) -> "SweepSpec":
        data = load_toml(path, {"sweep": dict, "fixed": dict, "params": dict})
        return cls.from_dict(data)

    @classmethod
    def from_dict(cls, data: dict) -> "SweepSpec":
        sweep = data.get("sweep", {})
        for k in sweep:
            if k not in ("mode", "samples", "seed"):
                raise ParameterError(f"sweep.{k}", sweep[k], "unknown key; known keys: mode, samples, seed")
        mode = sweep.get("mode", "grid")
        if mode not in ("grid", "lhs"):
            raise ParameterError("sweep.mode", mode, "must be 'grid' or 'lhs'")
        samples = int(sweep.get("samples", 0))
        if mode == "lhs" and not 1 <= samples <= 10_000_000:
            raise ParameterError("sweep.samples", samples, "an lhs sweep needs 1 to 10000000 samples")
        fixed = dict(data.get("fixed", {}))
        params = dict(data.get("params", {}))
        for name in list(fixed) + list(params):
            if name not in INPUTS:
                raise ParameterError(name, None, f"unknown parameter; known: {', '.join(INPUTS)}")
        for name, spec in params.items():
            if not isinstance(spec, dict) or not (("values" in spec) ^ ("range" in spec)):
                raise ParameterError(f"params.{name}", spec, "give exactly one of values = [...] or range = [lo, hi]")
            extra = set(spec) - {"values", "range", "steps"}
            if extra:
                raise ParameterError(f"params.{name}.{sorted(extra)[0]}", None, "known keys: values, range, steps")
            if "range" in spec:
                lo, hi = spec["range"]
                if not (isinstance(lo, (int, float)) and isinstance(hi, (int, float)) and lo <= hi):
                    raise ParameterError(f"params.{name}.range", spec["range"], "must be [lo, hi] numbers, lo <= hi")
                if mode == "grid" and int(spec.get("steps", 0)) < 1:
                    raise ParameterError(f"params.{name}.steps", spec.get("steps"), "a grid range needs steps >= 1")
        return cls(params, fixed, mode, samples, int(sweep.get("seed", 0)))

    def points(self) -> list[dict]:
        """Every design point (fixed values, then varied ones), in a deterministic order."""
        base = {k: v for k, (_, v) in INPUTS.items()}
        base.update(self.fixed)
        names = list(self.params)
        if self.mode == "grid":
            axes = []
            for n in names:
                s = self.params[n]
                axes.append(list(s["values"]) if "values" in s
                            else list(np.linspace(s["range"][0], s["range"][1], int(s["steps"]))))
            combos = itertools.product(*axes) if axes else [()]
        else:
            combos = self._lhs(names)
        pts = []
        for combo in combos:
            row = dict(base)
            row.update({n: (v.item() if isinstance(v, np.generic) else v) for n, v in zip(names, combo)})
            pts.append(row)
        return pts

    def _lhs(self, names: list[str]) -> list[tuple]:
        """Latin hypercube: each parameter's range cut into ``samples`` strata, one sample per stratum."""
        rng = np.random.default_rng(self.seed)
        n = self.samples
        cols = []
        for name in names:
            u = (rng.permutation(n) + rng.random(n)) / n
            s = self.params[name]
            if "range" in s:
                lo, hi = s["range"]
                cols.append(lo + u * (hi - lo))
            else:
                vals = list(s["values"])
                cols.append([vals[min(int(x * len(vals)), len(vals) - 1)] for x in u])
        return list(zip(*cols)) if cols else [()] * n


def point_id(point: dict) -> str:
    """Stable id of a design point: a hash of its inputs (so that --resume matches rows)."""
    key = json.dumps({k: point[k] for k in INPUTS}, sort_keys=True, default=float)
    return hashlib.sha1(key.encode()).hexdigest()[:12]


# --------------------------------------------------------------------------
# analytic mode: vectorised optimiser
# --------------------------------------------------------------------------


def _life_columns(rows: list[dict]) -> None:
    """Predicted life (median and 90 % interval, backlash 0.25 mm) of the feasible rows (rjcad.life)."""
    from rjcad import life

    ok = [r for r in rows if r.get("feasible")]
    if not ok:
        return
    m_end = np.array([sp.END_CONDITIONS[r["end"]][1] for r in ok])
    amp = np.array([m_end_i * 6.0 * r["spring_stiffness_nmm_per_rad"] * math.radians(float(r["rotation_deg"]))
                    / (2 * r["width_mm"] * r["thickness_mm"] ** 2) for m_end_i, r in zip(m_end, ok)])
    med, lo, hi = life.predict_cycles(amp, np.array([r["thickness_mm"] for r in ok]), 0.25)
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
            sp.SpringRequirement(float(pt["stiffness_nmm_per_rad"]), math.radians(float(pt["rotation_deg"])),
                                 math.radians(float(pt["preload_deg"])), pt["material"], pt["printer"],
                                 float(pt["safety_factor"]), pt["end"])
        except RjcadError as e:
            rows[i] = {**pt, "id": point_id(pt), "status": "failed", "feasible": False, "error": str(e)}
            continue
        key = (get_material(pt["material"]).key, get_printer(pt["printer"]).key, pt["end"])
        groups.setdefault(key, []).append(i)
    for (mat, prn, end), idx in groups.items():
        material, printer = get_material(mat), get_printer(prn)
        K = np.array([float(points[i]["stiffness_nmm_per_rad"]) for i in idx])
        rot = np.radians([float(points[i]["rotation_deg"]) for i in idx])
        pre = np.radians([float(points[i]["preload_deg"]) for i in idx])
        sf = np.array([float(points[i]["safety_factor"]) for i in idx])
        allow = material.yield_strength_mpa / sf
        res = optimise_arrays(K / 2, rot + pre, material=material, printer=printer, allowed_stress=allow, end=end)
        E = material.youngs_modulus_mpa
        Ks = sp.stiffness(E, res["width"], res["thickness"], res["length"], end)
        cols = {
            "width_mm": res["width"], "thickness_mm": res["thickness"], "length_mm": res["length"],
            "inner_radius_mm": res["inner_radius"], "pitch_mm": res["pitch"], "turns": res["turns"],
            "outer_radius_mm": res["outer_radius"], "spring_stiffness_nmm_per_rad": Ks,
            "joint_stiffness_nmm_per_rad": 2 * Ks, "max_stress_mpa": res["max_stress"],
            "allowed_stress_mpa": allow, "min_coil_gap_mm": res["min_coil_gap"],
        }
        for k, i in enumerate(idx):
            row = {**points[i], "id": point_id(points[i]), "material": mat, "printer": prn}
            if res["feasible"][k]:
                row.update({c: float(v[k]) for c, v in cols.items()})
                row.update(status="ok", feasible=True, binding="", error="",
                           stress_margin=float(allow[k] / res["max_stress"][k]))
            else:
                name = CONSTRAINTS[int(res["binding"][k])]
                row.update(status="infeasible", feasible=False, binding=name,
                           error=infeasible_message(name, float(res["binding_value"][k]),
                                                    float(res["binding_limit"][k]),
                                                    float(res["thickness"][k]), float(res["width"][k])))
            rows[i] = row
    out = [r for r in rows if r is not None]
    _life_columns(out)
    return out


# --------------------------------------------------------------------------
# build mode: one task per design (process pool or Dask)
# --------------------------------------------------------------------------


def build_task(point: dict, mesh_dir: str | None = None) -> dict:
    """Build and check the joint of one design point; never raises (a failure is a row)."""
    row = {**point, "id": point_id(point)}
    t0 = time.perf_counter()
    try:
        from rjcad.cad.build import build, render_files
        from rjcad.params import JointParams

        p = JointParams(stiffness=float(point["stiffness_nmm_per_rad"]),
                        rotation=math.radians(float(point["rotation_deg"])),
                        preload=math.radians(float(point["preload_deg"])), material=point["material"],
                        printer=point["printer"], safety_factor=float(point["safety_factor"]), end=point["end"],
                        clearance=float(point["clearance_mm"]), link_length=float(point["link_length_mm"]))
        b = build(p)
        row["build_s"] = time.perf_counter() - t0
        row.update({k: b.manifest["spring"][k] for k in DESIGN_KEYS})
        row["triangles"] = b.manifest["mesh"]["triangles"]
        row["measured_min_gap_mm"] = b.manifest["measured_min_gap_mm"]
        row.update(_check_joint(b))
        if mesh_dir:
            files = render_files(b, "joint", png=False)
            write_atomic(Path(mesh_dir) / f"{row['id']}.stl", files["joint.stl"])
        row.update(status="ok" if row["checks_passed"] else "check_failed", feasible=True, error="")
    except RjcadError as e:
        row.update(status="infeasible", feasible=False, error=str(e), build_s=time.perf_counter() - t0)
    except Exception as e:  # a design that raises is a failed row, never a crashed sweep
        row.update(status="failed", feasible=False, error=f"{type(e).__name__}: {e}", build_s=time.perf_counter() - t0)
    return row


def _check_joint(b) -> dict:
    """Run the print-readiness checks on a built joint (rjcad.check when present)."""
    try:
        from rjcad import check as chk
    except ImportError:
        chk = None
    if chk is not None and hasattr(chk, "run_checks"):
        rep = chk.run_checks(list(b.meshes.values()), manifest=b.manifest, clearance=b.manifest["clearance_mm"],
                             printer=b.manifest["printer"])
        d = rep.to_dict() if hasattr(rep, "to_dict") else rep
        failed = [c["name"] for c in d["checks"] if c["passed"] is False]
        return {"checks_passed": bool(d["passed"]), "checks_failed": ";".join(failed)}
    # fallback: the essential mesh checks
    import manifold3d as m3

    from rjcad.cad.build import to_manifold

    ok = all(m.is_watertight for m in b.meshes.values())
    mans = [to_manifold(m) for m in b.meshes.values()]
    ok &= all(m.status() == m3.Error.NoError for m in mans)
    gap = mans[0].min_gap(mans[1], 1.0)
    ok &= gap >= b.manifest["clearance_mm"] - 0.02
    return {"checks_passed": bool(ok), "checks_failed": "" if ok else "watertight/manifold/clearance"}


# --------------------------------------------------------------------------
# execution, progress, resume
# --------------------------------------------------------------------------


class Progress:
    """A progress bar with rate and ETA on a terminal; plain periodic lines otherwise."""

    def __init__(self, total: int, stream=None, every_s: float = 5.0):
        self.total, self.done, self.t0 = total, 0, time.perf_counter()
        self.stream = stream or sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.every_s, self.last = every_s, 0.0

    def update(self, n: int = 1) -> None:
        self.done += n
        now = time.perf_counter()
        if self.tty or now - self.last >= self.every_s or self.done == self.total:
            self.last = now
            el = now - self.t0
            rate = self.done / el if el > 0 else 0.0
            eta = (self.total - self.done) / rate if rate > 0 else float("inf")
            msg = f"{self.done}/{self.total} designs, {rate:.1f}/s, ETA {eta:.0f} s"
            if self.tty:
                w = 30
                fill = int(w * self.done / max(self.total, 1))
                self.stream.write(f"\r[{'#' * fill}{'.' * (w - fill)}] {msg}")
                if self.done == self.total:
                    self.stream.write("\n")
            else:
                self.stream.write(f"sweep: {msg}\n")
            self.stream.flush()


def _columns(rows: list[dict]) -> list[str]:
    cols = list(INPUTS) + ["id", "status", "feasible", "binding", "error"]
    for r in rows:
        for k in r:
            if k not in cols:
                cols.append(k)
    return cols


def read_results(path: Path) -> list[dict]:
    if not path.exists():
        return []
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def run_tasks(fn: Callable, points: list[dict], workers: int, scheduler: str | None,
              progress: Progress, on_row: Callable[[dict], None], **kw) -> None:
    """Run ``fn(point, **kw)`` for every point on a local process pool or a Dask cluster."""
    if not points:
        return
    if scheduler:
        from dask.distributed import Client, as_completed

        with Client(scheduler) as client:
            futures = [client.submit(fn, pt, pure=False, **kw) for pt in points]
            for fut in as_completed(futures):
                on_row(fut.result())
                progress.update()
        return
    if workers == 0:  # in this process (debugging, tests)
        for pt in points:
            on_row(fn(pt, **kw))
            progress.update()
        return
    from concurrent.futures import ProcessPoolExecutor, as_completed as done
    import multiprocessing as mp

    # forkserver where the platform has it: a clean server process imports CadQuery once (about 2 s) and
    # forks the workers from there, so they start at once; plain fork could inherit locked thread pools
    if "forkserver" in mp.get_all_start_methods():
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(["rjcad.cad.build", "rjcad.sweep"])
    else:
        ctx = mp.get_context("spawn")
    with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
        futs = [pool.submit(fn, pt, **kw) for pt in points]
        for fut in done(futs):
            on_row(fut.result())
            progress.update()


@dataclass
class SweepResult:
    rows: list[dict]
    computed: int
    skipped: int
    seconds: float


def run_sweep(spec: SweepSpec, out_dir: str | Path, *, build: bool = False, workers: int | None = None,
              scheduler: str | None = None, resume: bool = False, keep_meshes: bool = False,
              stream=None) -> SweepResult:
    """Run a sweep and write results.csv (+ .parquet), pareto.png and summary.md into ``out_dir``."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    points = spec.points()
    csv_path = out / "results.csv"
    partial = out / "results.partial.jsonl"
    done_rows = []
    if resume:
        done_rows = read_results(csv_path)
        if partial.exists():  # rows of an interrupted build-mode run
            seen = {r["id"] for r in done_rows}
            for line in partial.read_text().splitlines():
                try:
                    r = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a line cut by the interruption
                if r.get("id") not in seen:
                    done_rows.append(r)
                    seen.add(r["id"])
    done_ids = {r["id"] for r in done_rows}
    todo = [pt for pt in points if point_id(pt) not in done_ids]
    t0 = time.perf_counter()
    progress = Progress(len(todo), stream=stream)
    new_rows: list[dict] = []
    workers = (os.cpu_count() or 1) if workers is None else workers
    if build:
        with partial.open("a") as log:
            def keep(row):
                new_rows.append(row)
                log.write(json.dumps(row, default=str) + "\n")
                log.flush()
            mesh_dir = str(out / "meshes") if keep_meshes else None
            run_tasks(build_task, todo, workers, scheduler, progress, keep, mesh_dir=mesh_dir)
    else:
        chunk = 100_000
        for k in range(0, len(todo), chunk):
            part = analytic_rows(todo[k:k + chunk])
            new_rows.extend(part)
            progress.update(len(part))
    order = {point_id(pt): i for i, pt in enumerate(points)}
    rows = done_rows + new_rows
    rows.sort(key=lambda r: order.get(r["id"], len(order)))
    write_results(out, rows)
    write_report(out, rows, build=build)
    partial.unlink(missing_ok=True)
    return SweepResult(rows, len(new_rows), len(done_rows), time.perf_counter() - t0)


def write_results(out: Path, rows: list[dict]) -> None:
    cols = _columns(rows)
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols, extrasaction="ignore")
    w.writeheader()
    for r in rows:
        w.writerow({k: r.get(k, "") for k in cols})
    write_atomic(out / "results.csv", buf.getvalue())
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return
    table = pa.table({c: [str(r.get(c, "")) for r in rows] for c in cols})
    sink = pa.BufferOutputStream()
    pq.write_table(table, sink)
    write_atomic(out / "results.parquet", sink.getvalue().to_pybytes())


def pareto_front(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Indices of points not dominated when minimising x and maximising y."""
    order = np.lexsort((-y, x))
    front, best = [], -np.inf
    for i in order:
        if y[i] > best:
            front.append(i)
            best = y[i]
    return np.array(front, dtype=int)


def write_report(out: Path, rows: list[dict], build: bool) -> None:
    """pareto.png (outer radius vs stress margin, and vs life when known) and summary.md."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = [r for r in rows if str(r.get("feasible")) in ("True", "true", "1") and r.get("outer_radius_mm") not in ("", None)]
    has_life = any(r.get("predicted_cycles") not in ("", None) for r in ok)
    fig, axes = plt.subplots(1, 2 if has_life else 1, figsize=(12 if has_life else 7, 5), squeeze=False)
    mats = sorted({r["material"] for r in ok})
    for m_i, mat in enumerate(mats):
        sub = [r for r in ok if r["material"] == mat]
        x = np.array([float(r["outer_radius_mm"]) for r in sub])
        y = np.array([float(r["allowed_stress_mpa"]) / float(r["max_stress_mpa"]) for r in sub])
        c = f"C{m_i}"
        axes[0, 0].scatter(x, y, s=8, alpha=0.35, color=c)
        f = pareto_front(x, y)
        axes[0, 0].plot(x[f], y[f], "-o", ms=3, color=c, label=f"{mat} (Pareto front)")
        if has_life:
            lp = [(float(r["outer_radius_mm"]), float(r["predicted_cycles"])) for r in sub
                  if r.get("predicted_cycles") not in ("", None)]
            if lp:
                lx, ly = np.array(lp).T
                axes[0, 1].scatter(lx, ly, s=8, alpha=0.35, color=c)
                fl = pareto_front(lx, ly)
                axes[0, 1].plot(lx[fl], ly[fl], "-o", ms=3, color=c, label=mat)
    axes[0, 0].set_xlabel("outer radius [mm] (encumbrance)")
    axes[0, 0].set_ylabel("stress margin, allowed / peak [-]")
    axes[0, 0].set_title("Pareto front: small and safe")
    if mats:
        axes[0, 0].legend(fontsize=8)
    if has_life:
        axes[0, 1].set_yscale("log")
        axes[0, 1].set_xlabel("outer radius [mm]")
        axes[0, 1].set_ylabel("predicted cycles")
        axes[0, 1].legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    write_atomic(out / "pareto.png", buf.getvalue())

    n = len(rows)
    by_status: dict[str, int] = {}
    for r in rows:
        by_status[r.get("status", "")] = by_status.get(r.get("status", ""), 0) + 1
    binding: dict[str, int] = {}
    for r in rows:
        if r.get("binding"):
            binding[r["binding"]] = binding.get(r["binding"], 0) + 1
    lines = [f"# Sweep summary ({'build' if build else 'analytic'} mode)", "",
             f"- designs: {n}", *[f"- {k or 'unknown'}: {v}" for k, v in sorted(by_status.items())]]
    if binding:
        lines += ["", "## Binding constraints of the infeasible designs", "",
                  *[f"- {k}: {v}" for k, v in sorted(binding.items(), key=lambda kv: -kv[1])]]
    if ok:
        lines += ["", "## Smallest feasible spring per material", "", "| material | outer radius [mm] | "
                  "stiffness [N·mm/rad] | rotation [deg] | stress margin |", "|---|---|---|---|---|"]
        for mat in mats:
            best = min((r for r in ok if r["material"] == mat), key=lambda r: float(r["outer_radius_mm"]))
            lines.append(f"| {mat} | {float(best['outer_radius_mm']):.2f} | "
                         f"{float(best['stiffness_nmm_per_rad']):.2f} | {float(best['rotation_deg']):.0f} | "
                         f"{float(best['allowed_stress_mpa']) / float(best['max_stress_mpa']):.2f} |")
    if build:
        times = [float(r["build_s"]) for r in rows if r.get("build_s") not in ("", None)]
        if times:
            lines += ["", f"Build time per design: median {float(np.median(times)):.2f} s over {len(times)} designs."]
    write_atomic(out / "summary.md", "\n".join(lines) + "\n")
