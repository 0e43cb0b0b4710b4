"""Every benchmark keeps running and keeps reporting what it promises: a --quick smoke run of each (tiny sizes;
never a timed test: no time is asserted), its JSON keys, and each target its docstring states, reported as
{value, target, goal, met}."""

import ast
import json
import math
import re
import subprocess
import sys

import pytest

#: benchmark → (keys its JSON must hold, the targets it must report)
BENCHMARKS = {
    "check": (
        {
            "solid_mesh_triangles",
            "watertight_manifold_s",
            "watertight_manifold_tri_per_s",
            "joint_triangles",
            "joint_motion_sweep_s",
            "joint_motion_poses",
            "joint_clearance_s",
            "joint_min_feature_s",
            "repeats",
            "finger_triangles",
            "finger_overhang_s",
            "finger_slicer_s",
            "check_triangles",
            "check_seconds",
            "check_cpu_seconds",
            "check_scaling_exponent",
            "big_mesh_triangles",
            "big_check_s",
            "big_check_cpu_s",
            "big_check_peak_rss_gb",
            "finger_check_slicer_s",
            "finger_prusaslicer_alone_s",
            "finger_check_no_slicer_s",
            "finger_check_over_slicer",
        },
        {
            "watertight_manifold_tri_per_s",
            "joint_motion_sweep_s",
            "finger_overhang_s",
            "finger_slicer_s",
            "finger_check_over_slicer",
            "finger_check_no_slicer_s",
            "big_check_s",
            "big_check_peak_rss_gb",
        },
    ),
    "cli": (
        {
            "import_cli",
            "joint",
            "joint_one_process",
            "ratio_joint_over_joint_one_process",
            "finger",
            "spring",
            "check",
            "openscad",
            "openscad_version",
            "in_process_build_stl_step_s",
            "ratio_openscad_over_rjcad_joint",
            "ratio_openscad_over_in_process_build_stl_step",
            "repeats",
        },
        {"ratio_openscad_over_rjcad_joint", "saved_by_cad_process_s", "spring_s", "in_process_build_stl_step_s"},
    ),
    "finger": (
        {
            "median_build_s",
            "median_build_tessellate_measure_s",
            "ratio_time_n_over_n_time_1",
            "ratio_full_n_over_n_full_1",
            "repeats",
        },
        {"worst_ratio_time_n_over_n_time_1"},
    ),
    "grasp": ({"per_object", "rjcad_slowest_object_s"}, {"rjcad_s_per_object"}),
    "identify": (
        {
            "paper_campaign_s",
            "paper_campaign_cpu_s",
            "paper_campaign_load_s",
            "paper_campaign_effects",
            "samples_per_experiment",
            "seconds",
            "cpu_seconds",
            "effects_found",
            "us_per_sample",
            "scaling_exponent",
            "finger_campaign_s",
            "finger_campaign_cpu_s",
            "finger_campaign_found",
            "finger_solver_us_per_step",
            "finger_samples",
            "finger_campaign_threads_s",
            "outside_catalogue_campaign_s",
            "outside_catalogue_campaign_cpu_s",
            "finger_outside_catalogue_s",
            "finger_outside_catalogue_cpu_s",
        },
        {
            "paper_campaign_s",
            "outside_catalogue_campaign_s",
            "worst_scaling_exponent",
            "finger_campaign_worst_s",
            "finger_outside_catalogue_s",
        },
    ),
    "joint": (
        {
            "median_total_s",
            "median_cad_build_s",
            "median_tessellate_s",
            "median_measure_s",
            "median_stl_3mf_export_s",
            "median_step_export_s",
            "median_png_s",
            "png_share_of_total",
            "triangles",
            "stl_bytes",
            "stl_mb",
            "repeats",
        },
        {"median_total_s"},
    ),
    "life": (
        {
            "design_model_cold_fit_ms",
            "optimiser_ms_per_design_plain",
            "optimiser_ms_per_design_min_cycles",
            "min_cycles_vs_plain_ratio",
            "batched_designs_per_s_plain",
            "batched_designs_per_s_min_cycles",
            "batched_min_cycles_vs_plain_ratio",
            "critique_table_i_ms",
            "cli_spring_min_cycles_json_ms",
            "n",
            "repeats",
        },
        {"optimiser_ms_per_design_min_cycles"},
    ),
    "physics": (
        {
            "finger_steps",
            "finger_1000_step_stroke_s",
            "joint_samples_per_s",
            "joint_given_direction_samples_per_s",
            "joint_numpy_ceiling_samples_per_s",
            "joint_vs_numpy_ceiling",
            "joint_all_effects_nonuniform_t_samples_per_s",
            "inverse_design_s",
            "n",
            "repeats",
            "mujoco_default_finger_stroke_s",
            "rjcad_default_finger_stroke_s",
            "mujoco_over_rjcad",
            "mujoco_steps",
            "mujoco_vs_rjcad_max_deg",
        },
        {"finger_1000_step_stroke_s", "joint_samples_per_s", "mujoco_default_finger_stroke_s"},
    ),
    "spring": (
        {
            "optimiser_median_ms_per_design_paper_joint",
            "optimiser_median_ms_per_design_random",
            "optimiser_max_ms_per_design_random",
            "vector_designs",
            "numpy_plain_a_b3_over_c_per_s",
            "stiffness_evals_per_s",
            "stiffness_vs_numpy_ceiling",
            "full_model_evals_per_s",
            "full_model_vs_numpy_ceiling",
            "batched_optimiser_designs_per_s",
            "repeats",
        },
        {"rod_default_180deg_s", "optimiser_median_s_per_design_verified_paper_joint", "surrogate_designs_per_s"},
    ),
    "sweep": (
        {
            "analytic_designs",
            "analytic_designs_per_s",
            "analytic_designs_per_s_with_csv_and_plots",
            "build_designs",
            "build_wall_s_1_worker",
            "build_wall_s_2_workers",
            "parallel_efficiency_2_workers",
        },
        {"analytic_designs_per_s", "parallel_efficiency_2_workers"},
    ),
}

NUMBER = re.compile(r"(?<![\w.])\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def quick_run(root, name) -> dict:
    r = subprocess.run(
        [sys.executable, str(root / "benchmarks" / f"{name}.py"), "--quick"],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def positive_numbers(d: dict, keys) -> None:
    """Every numeric figure among ``keys`` (nested dicts and lists included) is a finite number > 0."""
    for k in keys:
        v = d[k]
        values = list(v.values()) if isinstance(v, dict) else v if isinstance(v, list) else [v]
        for x in values:
            if isinstance(x, (int, float)) and not isinstance(x, bool):
                assert math.isfinite(x) and x > 0, (k, x)


def test_every_benchmark_is_covered_and_uses_the_shared_timer(root):
    names = sorted(p.stem for p in (root / "benchmarks").glob("[!_]*.py"))
    assert names == sorted(BENCHMARKS)
    for name in names:
        text = (root / "benchmarks" / f"{name}.py").read_text()
        assert "from _timing import" in text and "perf_counter" not in text, name
        assert "--quick" in ast.get_docstring(ast.parse(text)), name


def check_grasp(d):
    """The quick run's 40 mm cylinder: both engines agree (issue #40's tolerances) with and without friction."""
    assert set(d["per_object"]) == {"40mm_mu0", "40mm_mu0.5"}
    for row in d["per_object"].values():
        assert row["max_angle_difference_deg"] < 2.0 and row["max_normal_force_difference_n"] < 0.05
        assert row["rjcad_s"] > 0 and row["mujoco_s"] > 0 and row["links_in_contact"] >= 1


def check_identify(d):
    assert d["paper_campaign_effects"] == ["coulomb_pin", "tendon_pin_friction", "capstan_path"]
    assert d["samples_per_experiment"] == [600, 1200] and all(s > 0 for s in d["seconds"])
    assert len(d["scaling_exponent"]) == 1
    assert d["finger_campaign_found"] == {"moment_arm": ["moment_arm"]} and d["finger_samples"] == 300
    assert d["finger_solver_us_per_step"]["angles"] > 0 and d["finger_solver_us_per_step"]["closure"] > 0
    assert d["finger_solver_us_per_step"]["angles_weight"] > 0 and d["finger_solver_us_per_step"]["closure_weight"] > 0
    assert len(d["cpu_seconds"]) == 2 and d["finger_campaign_cpu_s"]["moment_arm"] > 0  # CPU time, beside wall time
    # a stiffness drifting ±5 % over each run, outside the catalogue: the paper's effects and the drift proposed
    assert d["outside_catalogue_proposed"] == ["stiffness_drift"]
    assert d["outside_catalogue_effects"] == ["coulomb_pin", "tendon_pin_friction", "capstan_path"]
    # every spring of the default finger drifting ±5 % over each run, outside the finger catalogue
    assert d["finger_outside_catalogue_proposed"] == ["stiffness_drift"] and d["finger_outside_catalogue_effects"] == []


def check_physics(d):
    assert d["finger_steps"] == 41 and d["n"] == 2000
    assert d["mujoco_steps"] == 41 and d["mujoco_vs_rjcad_max_deg"] < 1.0


def check_finger(d):
    assert set(d["median_build_s"]) == {"1", "2"} and d["ratio_time_n_over_n_time_1"]["2"] > 0


def check_check(d):
    assert d["joint_motion_poses"] > 0
    assert d["targets"]["watertight_manifold_tri_per_s"]["value"] is None  # quick: far below the 1M-triangle mesh
    assert d["targets"]["finger_slicer_s"]["value"] is None  # quick: no slicing
    sizes = d["check_triangles"]
    assert sizes == sorted(sizes) and sizes[-1] == d["big_mesh_triangles"] and sizes[-1] > sizes[0]
    checks = {
        "load",
        "watertight",
        "manifold",
        "bodies",
        "simplify",
        "clearance",
        "motion",
        "min_feature",
        "bed",
        "overhang",
    }
    assert set(d["check_seconds"]) == set(d["check_cpu_seconds"]) == set(d["check_scaling_exponent"]) == checks
    assert all(len(v) == len(sizes) and min(v) > 0 for v in d["check_seconds"].values())
    assert all(len(v) == len(sizes) and min(v) >= 0 for v in d["check_cpu_seconds"].values())
    assert d["big_check_exit_code"] == 0  # the refined joint passes every check
    assert d["targets"]["big_check_s"]["value"] is None  # quick: far below 1.5 M triangles


def check_cli(d):
    for command in ("import_cli", "joint", "joint_one_process", "spring", "check"):
        assert d[command]["median_s"] > 0 and len(d[command]["runs_s"]) == d["repeats"]
    assert d["openscad"] is None and d["targets"]["ratio_openscad_over_rjcad_joint"]["value"] is None  # quick


EXTRA = {
    "cli": check_cli,
    "grasp": check_grasp,
    "identify": check_identify,
    "physics": check_physics,
    "finger": check_finger,
    "check": check_check,
}


@pytest.mark.parametrize("name", sorted(BENCHMARKS))
def test_benchmark_reports_its_keys_and_targets(root, name):
    keys, targets = BENCHMARKS[name]
    d = quick_run(root, name)
    assert keys <= set(d), keys - set(d)
    positive_numbers(d, keys - {"scaling_exponent", "check_scaling_exponent"})  # an exponent may be < 0 on tiny sizes
    assert set(d["targets"]) == targets
    doc = ast.get_docstring(ast.parse((root / "benchmarks" / f"{name}.py").read_text()))
    stated = {float(x) for x in NUMBER.findall(doc)}
    for tname, t in d["targets"].items():
        assert set(t) == {"value", "target", "goal", "met"}, tname
        assert t["target"] in stated, f"{name}: target {tname} = {t['target']} is not the one its docstring states"
        assert t["goal"] in ("at most", "at least")
        if t["value"] is None:  # not measured in this run (e.g. a target stated for a bigger size)
            assert t["met"] is None
        else:
            met = t["value"] <= t["target"] if t["goal"] == "at most" else t["value"] >= t["target"]
            assert t["met"] is met, tname
    EXTRA.get(name, lambda _: None)(d)
