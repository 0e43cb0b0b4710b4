"""Shared test set-up: Hypothesis profiles, the `root`, `cli`, `cli_process` and `summary_line` fixtures, the
`slow` auto-mark, and the "designs built" section at the end of the run.

Slow tests are found, not listed: at collection every test's code is read (with the helpers and fixtures it
reaches in tests/), and a test is marked `slow` when it builds a joint or a finger (OpenCASCADE), runs a
subprocess, starts a process pool or a Dask cluster, or looks for PrusaSlicer. CPU-heavy tests that no rule
finds (property runs of many examples, statistical fits, whole identify reports) are listed, by measurement,
in MEASURED_SLOW. `pytest -m 'not slow'` (`make test-fast`) then runs the rest, plus the tests marked
`fast_lane` (one real joint build, kept on purpose).
"""

from __future__ import annotations

import ast
import collections
import functools
import inspect
import os
import subprocess
import sys
from pathlib import Path
from typing import NamedTuple

import pytest
from hypothesis import HealthCheck, settings

# CI (the default): the same examples every run, so that a landing never depends on luck;
# HYPOTHESIS_PROFILE=dev explores new random examples.
settings.register_profile("ci", deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
settings.register_profile("dev", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

ROOT = Path(__file__).resolve().parents[1]
TESTS = Path(__file__).resolve().parent


# ---------------------------------------------------------------- fixtures


@pytest.fixture(scope="session")
def root() -> Path:
    """The repository's root directory."""
    return ROOT


class CliRun(NamedTuple):
    """What one in-process `rjcad` run gave: exit code, stdout, stderr."""

    code: int
    out: str
    err: str


def _argv(args) -> list[str]:
    """``("spring", "--json")`` or ``(["spring", "--json"],)`` → ``["spring", "--json"]``."""
    if len(args) == 1 and isinstance(args[0], (list, tuple)):
        args = args[0]
    return [str(a) for a in args]


@pytest.fixture
def cli(capsys):
    """Run `rjcad ARGS…` in this process: ``code, out, err = cli("spring", "--json")`` (or ``cli([...])``).

    The command must exit (click's standalone mode always does); its output is taken from ``capsys``.
    """
    from rjcad.cli import main

    def run(*args) -> CliRun:
        with pytest.raises(SystemExit) as e:
            main(_argv(args))
        out, err = capsys.readouterr()
        return CliRun(e.value.code, out, err)

    return run


@pytest.fixture
def cli_process():
    """Run `python -m rjcad ARGS…` in a subprocess from the repository root: a text ``CompletedProcess``."""

    def run(*args, timeout: float = 300) -> subprocess.CompletedProcess:
        return subprocess.run(
            [sys.executable, "-m", "rjcad", *_argv(args)], capture_output=True, text=True, timeout=timeout, cwd=ROOT
        )

    return run


# ---------------------------------------------------------------- designs built (the terminal summary's section)

_SUMMARY = pytest.StashKey[list]()
#: CAD builds in this process: "joint modules" (rjcad.cad.joint.build_joint), "fingers" (rjcad.cad.finger.build_finger).
_BUILT: collections.Counter = collections.Counter()
#: tests/shared_builds.py's counts, summed over the test processes.
_SHARED: collections.Counter = collections.Counter()


@pytest.fixture
def summary_line(request):
    """``summary_line(text)``: a line for the "designs built" section of the terminal summary, which pytest shows at
    the end of the run without ``-s`` (the property tests report how many random designs they built)."""
    return request.config.stash.setdefault(_SUMMARY, []).append


def _count_calls(module, name: str, kind: str) -> None:
    """Replace ``module.name`` by a wrapper that counts its calls in _BUILT[kind]."""
    fn = getattr(module, name)

    @functools.wraps(fn)
    def counted(*args, **kwargs):
        _BUILT[kind] += 1
        return fn(*args, **kwargs)

    setattr(module, name, counted)


def pytest_sessionstart(session):
    # before any test module imports the builders (rjcad.cad.build binds build_joint when it is imported)
    import rjcad.cad.finger
    import rjcad.cad.joint

    _count_calls(rjcad.cad.joint, "build_joint", "joint modules")
    _count_calls(rjcad.cad.finger, "build_finger", "fingers")


def pytest_sessionfinish(session):
    """Under pytest-xdist, a worker hands its lines and counts to the controller, which prints the section."""
    out = getattr(session.config, "workeroutput", None)
    if out is not None:
        out["rjcad_summary"] = list(session.config.stash.get(_SUMMARY, []))
        out["rjcad_built"] = dict(_BUILT)
        out["rjcad_shared"] = _shared_stats()


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """pytest-xdist's controller: a worker finished; add its "designs built" lines and CAD build counts."""
    out = getattr(node, "workeroutput", {})
    node.config.stash.setdefault(_SUMMARY, []).extend(out.get("rjcad_summary", []))
    _BUILT.update(out.get("rjcad_built", {}))
    _SHARED.update(out.get("rjcad_shared", {}))


def _shared_stats() -> dict:
    """tests/shared_builds.py's counts in this process (none if no test imported it)."""
    mod = sys.modules.get("shared_builds")
    return dict(mod.STATS) if mod is not None else {}


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    lines = config.stash.get(_SUMMARY, [])
    if getattr(config, "workerinput", None) is None and not hasattr(config, "workeroutput"):
        _SHARED.update(_shared_stats())  # without pytest-xdist: this process's own
    if _BUILT:
        lines = lines + [
            f"CAD builds in this run (random and fixed designs; not those in CLI subprocesses or sweep "
            f"workers): {', '.join(f'{kind} {n}' for kind, n in sorted(_BUILT.items()))}"
        ]
    if any(_SHARED.values()):
        lines = lines + [
            f"shared designs (tests/shared_builds.py, per test process): built {_SHARED['built']}, "
            f"handed out again {_SHARED['reused']}; checked {_SHARED['checked']}, report handed out "
            f"again {_SHARED['check reused']}"
        ]
    if lines:
        terminalreporter.write_sep("=", "designs built")
        for line in lines:
            terminalreporter.write_line(line)


# ---------------------------------------------------------------- the slow auto-mark

#: Functions that build a whole joint or finger's solids (by the name they are called with).
CAD_BUILDERS = {"build", "build_joint", "build_finger", "build_finger_model", "write_joint", "write_finger"}
#: CLI commands that build CAD when their input is valid.
CAD_COMMANDS = {"joint", "finger"}
#: Names through which tests run the CLI.
CLI_RUNNERS = {"main", "cli", "cli_process"}
#: Process pools and clusters.
POOLS = {"LocalCluster", "Client", "ProcessPoolExecutor", "Pool"}


#: Tests of more than about 3 s that the rules above do not find, by node id (a parametrised test's name alone:
#: every case) → seconds measured with `pytest -p no:xdist -m 'not slow' --durations=60` on the 2-core machine
#: under load (issue #33: 623 s for the fast lane, 480 s of it in these). Re-measure when the fast lane slows.
MEASURED_SLOW = {
    "tests/test_bearing_finger.py::test_a_grasp_with_the_bearings_friction": 12,  # three grasps
    "tests/test_bearing_finger.py::test_the_fingers_closure_is_each_joints_own_bearing_balance": 4,
    "tests/test_bearing_finger.py::test_the_locking_mu_is_where_the_self_consistent_drive_fails": 3,
    "tests/test_spring_properties.py::test_feasible_requirements_of_the_paper_family": 36,
    "tests/test_identify_report.py::test_null_case": 35,  # the module's three identify reports (fixtures)
    "tests/test_identify_report.py::test_all_files_written_and_pngs_are_images": 30,
    "tests/test_identify_report.py::test_effects_causes_and_step_table": 30,
    "tests/test_identify_report.py::test_experiment_table_params_and_noise_floor": 30,
    "tests/test_identify_report.py::test_dropped_step_and_notes_render": 30,
    "tests/test_identify_report.py::test_not_identifiable_section": 7,
    "tests/test_identify_report.py::test_rerun_is_byte_identical_and_bad_out_dir": 12,
    "tests/test_life.py::test_life_constraint_property": 28,
    "tests/test_physics_coupled.py::test_random_heavy_fingers_balance_at_every_reading": 21,
    "tests/test_physics_coupled.py::test_joints_sliding_against_their_weight_settle": 8,
    "tests/test_identify_finger.py::test_cli_bench_and_identify_finger": 10,  # in-process (was 3 processes)
    "tests/test_sweep.py::test_example_sweep_matches_rjcad_spring": 15,
    "tests/test_sweep.py::test_resume_does_not_recompute": 5,
    "tests/test_sweep.py::test_infeasible_rows_carry_the_binding_constraint": 3,
    "tests/test_spring_surrogate.py::test_random_designs_within_the_margin": 15,
    # each hidden effect of the catalogue found (3-4 s each under -n 2); coulomb_pin and viscous stay in the fast lane
    **{
        f"tests/test_identify.py::test_hidden_effect_is_found_named_and_measured[{e}]": 3
        for e in ("spring_calibration", "tendon_pin_friction", "capstan_path", "stiffening", "relaxation")
    },
    "tests/test_identify.py::test_hidden_combinations[effects1]": 3,
    "tests/test_identify.py::test_hidden_combinations[effects2]": 6,
    "tests/test_identify.py::test_hidden_combinations[effects3]": 5,
    "tests/test_identify.py::test_backward_pass_corrects_an_early_choice_on_constant_speed_data": 5,
    "tests/test_identify_ambiguity.py::test_viscous_unbiased_under_angle_noise": 12,
    "tests/test_identify_doc.py::test_doc_quotes_the_current_numbers": 4,
    "tests/test_physics_finger.py::test_relaxation_tension_decays_to_the_relaxed_value_during_a_hold": 5,
    "tests/test_physics_inverse.py::test_reachable_targets_end_within_a_degree_in_order": 16,
    "tests/test_physics_inverse.py::test_inverse_design_reaches_the_target[proximal-first]": 4,
    "tests/test_joint_properties.py::test_the_desktop_cup_holds_its_stop_lugs_and_clears_the_flare[kw4]": 4,
    "tests/test_optimiser.py::test_papers_printer_allows_thinner_strips": 4,
    "tests/test_optimiser.py::test_vectorised_optimiser_matches_scalar_designs": 4,
    "tests/test_spring_verified.py::test_old_default_design_is_refused_by_the_verification": 4,
    "tests/test_spring_verified.py::test_verification_catches_an_optimistic_table": 3,
    "tests/test_life.py::test_selection_frequencies_small_run": 4,
    "tests/test_life_cli.py::test_doc_regenerates_and_the_committed_doc_is_current": 7,
    "tests/test_life.py::test_table_i_stresses_from_the_rod_model[1]": 3,
    "tests/test_life.py::test_table_i_stresses_from_the_rod_model[4]": 3,
    "tests/test_untrusted.py::test_bad_designs_are_rows_with_their_error": 4,
    "tests/test_sweep_resume.py::test_resume_on_a_damaged_results_csv_keeps_every_intact_row_once": 36,
    "tests/test_sweep_resume.py::test_a_design_named_twice_is_one_row": 3,
}


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "fast_lane: builds CAD but stays in `-m 'not slow'` on purpose (say why in the docstring)"
    )


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.get_closest_marker("fast_lane") or item.get_closest_marker("slow"):
            continue
        why = slow_reason(item)
        if why:
            item.add_marker(pytest.mark.slow(why=why))
    workers = int(getattr(config, "workerinput", {}).get("workercount", 1))
    if workers > 1:
        items[:] = deal_longest(items, workers)


# ---------------------------------------------------------------- the longest tests first (pytest-xdist)

#: The longest tests, longest first (node id, or a parametrised test's name for every case; seconds under `-n 2`
#: on the 2-core machine, issue #33). Each one alone outlasts hundreds of short tests: started last, it would be
#: the run's tail.
LONGEST = {
    # the full run of 2026-11-27 (1254 tests in 646 s, -n 2, idle 2-core machine), seconds
    "tests/test_desktop.py::test_random_desktop_designs_pass_every_check_with_supports_off": 143,
    "tests/test_joint_properties.py::test_random_accepted_joints_build_checked_meshes": 115,
    "tests/test_fuzz_corpus.py::test_every_case_keeps_the_promise": 87,
    "tests/test_finger_properties.py::test_random_accepted_fingers_build_checked_meshes": 81,
    # pre-commit builds rjcad's own environment; the documented CI workflow builds and slices the default finger
    "tests/test_ci_check.py::test_the_python_hook_installs_rjcad_and_runs": 32,
    "tests/test_ci_check.py::test_the_documented_workflow_checks_the_default_finger_one_case_per_check": 24,
    "tests/test_identify_finger.py::test_degenerate_pair_is_reported_not_fitted": 18,
    "tests/test_sweep.py::test_dask_cluster_gives_the_same_results_as_the_local_run": 17,
    # the fresh-clone CI runs of 2026-11-27 (716 and 787 s): the next longest, started early so none is the tail
    "tests/test_spring_properties.py::test_optimiser_is_the_smallest_or_rightly_infeasible": 40,
    "tests/test_benchmarks.py::test_benchmark_reports_its_keys_and_targets": 15,
    "tests/test_finger.py::test_default_finger_passes_every_check_with_supports_off": 20,
    "tests/test_identify_finger.py::test_hidden_pairs": 14,
}


def _longest_key(item) -> str | None:
    node = item.nodeid.replace(os.sep, "/")
    return next((k for k in (node, node.split("[")[0]) if k in LONGEST), None)


def deal_longest(items: list, workers: int) -> list:
    """``items`` reordered for ``--dist worksteal``, which hands worker k the k-th of ``workers`` consecutive
    slices (each the remaining count over the workers left): the LONGEST tests dealt round the slices, longest
    first, each slice starting with its share; the other tests in their order (a module's tests stay together)."""
    longest = sorted((it for it in items if _longest_key(it)), key=lambda it: -LONGEST[_longest_key(it)])
    rest = [it for it in items if not _longest_key(it)]
    out, left = [], len(items)
    for k in range(workers):
        size = left // (workers - k)
        head = longest[k::workers]
        take = max(0, size - len(head))
        out += head + rest[:take]
        rest = rest[take:]
        left -= size
    return out + rest


def slow_reason(item) -> str | None:
    """Why ``item`` is slow (MEASURED_SLOW, its code, the tests/ helpers it calls, its fixtures), or None."""
    node = item.nodeid.replace(os.sep, "/")
    for key in (node, node.split("[")[0]):
        if key in MEASURED_SLOW:
            return f"measured {MEASURED_SLOW[key]} s"
    fns = [getattr(item, "function", None)]
    defs = getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {})
    for name in item.fixturenames:
        fns += [d.func for d in defs.get(name, ())]
    for fn in fns:
        why = function_slow_reason(fn)
        if why:
            return why
    return None


def function_slow_reason(fn) -> str | None:
    """Why calling ``fn`` (a test, fixture or helper defined in tests/) is slow, or None."""
    return _reason(fn, set())


def _in_tests(fn) -> bool:
    code = getattr(fn, "__code__", None)
    return code is not None and _file_in_tests(code.co_filename)


@functools.cache
def _file_in_tests(filename: str) -> bool:
    return Path(filename).resolve().parent == TESTS


_CACHE: dict = {}


@functools.cache
def _defs(filename: str) -> dict:
    """Each function defined in a file, by its first line (the first decorator's, as ``co_firstlineno`` counts
    it) → its AST: a file is parsed once, not a function's source found again by tokenizing for each call."""
    try:
        tree = ast.parse(Path(filename).read_text())
    except (OSError, SyntaxError, UnicodeDecodeError):
        return {}
    out = {}
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            out[min([node.lineno, *(d.lineno for d in node.decorator_list)])] = node
    return out


def _reason(fn, seen: set) -> str | None:
    """Slow reason of a function defined in tests/, following calls to other functions defined there."""
    if fn is None or not callable(fn):
        return None
    fn = inspect.unwrap(getattr(getattr(fn, "hypothesis", None), "inner_test", fn))  # through @given
    if fn in seen or not _in_tests(fn):
        return None
    seen.add(fn)
    if fn not in _CACHE:
        tree = _defs(fn.__code__.co_filename).get(fn.__code__.co_firstlineno)
        _CACHE[fn] = (own_slow_reason(tree), _called_names(tree)) if tree else (None, set())
    own, called = _CACHE[fn]
    if own:
        return own
    scope = getattr(fn, "__globals__", {})
    for name in called:
        why = _reason(scope.get(name), seen)
        if why:
            return f"{why} (in {name})"
    return None


def _called_names(tree) -> set[str]:
    return {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}


def own_slow_reason(tree) -> str | None:
    """The first slow thing this code does itself (see the module docstring)."""
    expects_usage_error = any(_is_exit_2_check(n) for n in ast.walk(tree) if isinstance(n, ast.Compare))
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and node.value == "prusa-slicer":
            return "looks for PrusaSlicer"
        if not isinstance(node, ast.Call):
            continue
        name = _func_name(node.func)
        if name in CAD_BUILDERS:
            return f"builds CAD ({name})"
        if isinstance(node.func, ast.Attribute) and _func_name(node.func.value) == "subprocess":
            return "runs a subprocess"
        if name in POOLS:
            return f"starts a process pool ({name})"
        kw = {k.arg: k.value for k in node.keywords}
        if isinstance(kw.get("build"), ast.Constant) and kw["build"].value is True:
            return "builds CAD (build=True)"
        if name in CLI_RUNNERS and not expects_usage_error:
            argv = _literal_args(node)
            if argv[:1] and argv[0] in CAD_COMMANDS:
                return f"builds CAD (rjcad {argv[0]})"
            if "--build" in argv:
                return "builds CAD (--build)"
    return None


def _func_name(f) -> str | None:
    if isinstance(f, ast.Name):
        return f.id
    if isinstance(f, ast.Attribute):
        return f.attr
    return None


def _literal_args(call: ast.Call) -> list:
    """The string constants a CLI call passes, in order: ``main(["joint", …])`` or ``cli("joint", …)``."""
    args = call.args
    if len(args) >= 1 and isinstance(args[0], (ast.List, ast.Tuple)):
        args = args[0].elts
    return [a.value if isinstance(a, ast.Constant) else None for a in args]


def _is_exit_2_check(node: ast.Compare) -> bool:
    """``… code == 2`` or ``… returncode == 2``: the run is expected to stop at a usage error, before any CAD."""
    sides = [node.left, *node.comparators]
    has_2 = any(isinstance(s, ast.Constant) and s.value == 2 for s in sides)
    return has_2 and any(_func_name(s) in ("code", "returncode") for s in sides)
