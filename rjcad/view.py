"""``rjcad view``: one self-contained HTML page of a built finger (or joint) that animates its closure.

The page holds everything it needs, so it opens from disk with no network: three.js (vendored from the npm
registry at setup time into ``rjcad/data/vendor/``, inlined as a module), the bodies as the builder's GLB
(base64), and the closure from ``rjcad.physics.finger.simulate_stroke`` (the same model and numbers as
``rjcad simulate finger MANIFEST --json``). A slider runs over the pull's tendon stroke; each link turns about
its joint's axis (the manifest's ``axis_point_mm``, ``axis_dir``) by the physics' angle, children with their
parents. The page reports the current angles and tension in ``#readout`` and ``window.rjcad``.
With objects (``rjcad view --object``, issue #40) the slider runs instead over the readings of rjcad's closure on
them (``rjcad.physics.grasp.close_on``, the tension ramped, the manifest's outlines: ``simulate finger --object``'s
numbers); the page draws each object across the flexion plane at its pose per reading and an arrow per contact
force on it (``grasp`` in the page's data), and states the arrows' scale, the tension and the grasp's verdict.
Units: mm and N in the page's data (the manifest's frame, +Z up), degrees in its display. The scene is the GLB's
frame (glTF's: metres, +Y up): the page maps the joints' axes and the tendon into it by the matrix the GLB states
(``frame``, from ``asset.extras``; an rjcad GLB written before it stated one is in the manifest's frame).
"""

from __future__ import annotations

import base64
import importlib.resources
import json
import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rjcad.errors import RjcadError
from rjcad.physics.grasp_result import arrow_scale

if TYPE_CHECKING:
    from rjcad.physics.grasp_result import Grasp
    from rjcad.physics.objects import Object

THREE_FILE = "three.module.min.js"
#: Samples of the closure over the pull: the same default as ``rjcad simulate finger --steps``.
DEFAULT_STEPS = 500
#: The page template, in rjcad/data/.
TEMPLATE = "viewer.html"


class ViewerError(RjcadError):
    """The viewer cannot be written (a missing GLB beside the manifest, three.js not vendored)."""


def vendored_three() -> str:
    """The vendored three.js module's source (fetched from the npm registry when a wheel is built, or by ``make vendor``)."""
    f = importlib.resources.files("rjcad") / "data" / "vendor" / THREE_FILE
    if not f.is_file():
        raise ViewerError(
            f"rjcad/data/vendor/{THREE_FILE} is missing: run `python tools/vendor_three.py` (make vendor) in the checkout once"
        )
    return f.read_text(encoding="utf-8")


def chains(joints: list[dict]) -> dict[str, list[int]]:
    """Per body, the joints (indices, root first) whose rotation moves it: those between the root and it."""
    parent_joint = {j["child"]: i for i, j in enumerate(joints)}
    out: dict[str, list[int]] = {}
    for j in joints:
        for name in (j["parent"], j["child"]):
            path: list[int] = []
            body = name
            while body in parent_joint:
                k = parent_joint[body]
                path.insert(0, k)
                body = joints[k]["parent"]
            out[name] = path
    return out


def tendon_owner(path_mm: list[list[float]], joints: list[dict]) -> list[str]:
    """The body each rest tendon point moves with: the parent of the first joint whose axis is beyond it
    along the finger (+X), else the last child."""
    xs = [j["axis_point_mm"][0] for j in joints]
    return [next((joints[i]["parent"] for i, x in enumerate(xs) if p[0] < x), joints[-1]["child"]) for p in path_mm]


def read_built(manifest_path: str | Path, allow_outside: bool = False) -> tuple[dict, bytes]:
    """A built finger's (or joint's) manifest (JSON object) and the GLB beside it (same stem; inside the manifest's
    folder, symlinks followed, unless ``allow_outside``)."""
    from rjcad.io.manifest import Manifest
    from rjcad.io.untrusted import confined, read_bytes, regular_or_absent

    path = Path(manifest_path)
    man = Manifest.read(str(path)).to_json()
    glb = confined(path.parent, path.with_suffix(".glb").name, str(path), allow_outside)
    if not regular_or_absent(glb):
        raise ViewerError(
            f"{glb}: not found (the GLB that `rjcad finger` writes beside {path.name}; rebuild to get it)"
        )
    data = read_bytes(glb, "mesh")
    glb_frame(data, str(glb))  # a damaged GLB is refused before the simulation
    return man, data


#: The identity, column-major: the frame of an rjcad GLB that states none (mm, +Z up, as the manifest).
SAME_FRAME = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]


def glb_frame(glb: bytes, name: str = "GLB") -> list[float]:
    """The map from the manifest's frame [mm, +Z up] to the GLB's (4×4, column-major), as its ``asset.extras``
    state it (``rjcad.cad.mesh_export.GLTF_FRAME``: metres, +Y up); ``SAME_FRAME`` when it states none."""
    from rjcad.cad.mesh_export import glb_json_chunk
    from rjcad.io.untrusted import decode, parse_json

    try:
        raw = glb_json_chunk(glb)
    except ValueError as e:
        raise ViewerError(f"{name}: not a GLB ({e}); rebuild to get it") from None
    doc = parse_json(decode(raw, name, "JSON"), name)  # its JSON, as any user's: limits, one error line
    asset = doc.get("asset") if isinstance(doc, dict) else None
    extras = asset.get("extras") if isinstance(asset, dict) else None
    if not isinstance(extras, dict) or "source_to_gltf_matrix" not in extras:
        return list(SAME_FRAME)
    m = extras["source_to_gltf_matrix"]
    if not (
        isinstance(m, list)
        and len(m) == 16
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in m)
    ):
        raise ViewerError(f"{name}: asset.extras.source_to_gltf_matrix is not 16 finite numbers; rebuild to get it")
    return [float(v) for v in m]


def page_data(
    man: dict,
    glb: bytes,
    title: str,
    stroke: float,
    steps: int,
    mu_t: float = 0.0,
    grasp: Grasp | None = None,
    bearing_mu: float | None = None,
) -> dict:
    """What the page needs besides three.js: bodies (GLB base64), joints, tendon path and the closure
    (the pull, ``steps + 1`` samples from 0 to ``stroke`` mm, the joints' friction from their bearings at
    ``bearing_mu`` if given; or, with ``grasp``, its readings and ``grasp``)."""
    joints = [
        {"parent": j["parent"], "child": j["child"], "axis_point_mm": j["axis_point_mm"], "axis_dir": j["axis_dir"]}
        for j in man["joints"]
    ]
    tendon = man.get("tendon_path_mm") or []
    data = {
        "title": title,
        "glb_base64": base64.b64encode(glb).decode("ascii"),
        "frame": glb_frame(glb),
        "joints": joints,
        "chains": chains(joints),
        "tendon_mm": tendon,
        "tendon_owner": tendon_owner(tendon, joints) if tendon else [],
    }
    from rjcad.physics.finger import model_from_manifest, simulate_stroke

    if grasp is not None:
        return data | grasp_page_data(grasp, sum(model_from_manifest(man).link_length), mu_t)
    c = simulate_stroke(finger_model(man, mu_t, bearing_mu), stroke, steps=steps)
    pull = slice(0, steps + 1)
    data["closure"] = {
        "stroke_mm": stroke,
        "steps": steps,
        "mu_t": mu_t,
        "tendon_mm": c.tendon_mm[pull].tolist(),
        "theta_deg": [[math.degrees(v) for v in row] for row in c.theta[pull].tolist()],
        "tension_n": c.tension[pull].tolist(),
    } | ({} if bearing_mu is None else {"bearing_mu": bearing_mu})
    return data


def force_arrows(g: Grasp, mm_per_n: float) -> list[list[list[float]]]:
    """Per reading, per contact (``g.contacts``' order), the arrow of the force on the object in the base's frame
    [mm]: [x0, y0, x1, y1] from the contact point along f = F_n n + F_t t (t: n turned +90°), ``mm_per_n`` long per N."""
    out = []
    for cs in g.contacts:
        row = []
        for c in cs:
            (x, y), (fx, fy) = c.point_mm, c.force
            row.append([float(x), float(y), float(x + fx * mm_per_n), float(y + fy * mm_per_n)])
        out.append(row)
    return out


def grasp_page_data(g: Grasp, finger_mm: float, mu_t: float = 0.0) -> dict:
    """The page's ``closure`` (the slider: one step per reading of ``g``) and ``grasp`` (``Grasp.to_dict()``, the
    arrows ``arrows_mm`` per reading and their scale ``arrow_mm_per_n``: the largest force over the readings is
    ``ARROW_FRACTION`` of the finger's length ``finger_mm``)."""
    d = g.to_dict()
    scale = arrow_scale((c for cs in g.contacts for c in cs), finger_mm)
    d["arrow_mm_per_n"] = scale
    d["arrows_mm"] = force_arrows(g, scale)
    closure = {
        "stroke_mm": g.tendon_mm[-1],
        "steps": len(g.tendon_mm) - 1,
        "mu_t": mu_t,
        "tendon_mm": d["tendon_mm"],
        "theta_deg": d["theta_deg"],
        "tension_n": d["tension_n"],
    }
    return {"closure": closure, "grasp": d}


def viewer_html(
    man: dict,
    glb: bytes,
    title: str,
    stroke: float,
    steps: int,
    mu_t: float = 0.0,
    grasp: Grasp | None = None,
    bearing_mu: float | None = None,
) -> str:
    """The self-contained page of the built finger ``man`` (manifest JSON object) whose bodies are ``glb``
    (with ``grasp``: its closure on objects)."""
    three = vendored_three()
    data = page_data(man, glb, title, stroke, steps, mu_t, grasp, bearing_mu)
    template = (importlib.resources.files("rjcad") / "data" / TEMPLATE).read_text(encoding="utf-8")
    three_url = "data:text/javascript;base64," + base64.b64encode(three.encode("utf-8")).decode("ascii")
    # "</" cannot end the script element inside JSON: written "<\/". One pass: no value is scanned again.
    values = {
        "THREE_URL": three_url,
        "TITLE": _html_text(title),
        "DATA": json.dumps(data, separators=(",", ":")).replace("</", "<\\/"),
    }
    return re.sub(r"@@([A-Z_]+)@@", lambda m: values[m.group(1)], template)


def _html_text(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def finger_model(man: dict, mu_t: float = 0.0, bearing_mu: float | None = None) -> Any:
    """The finger model of the manifest ``man`` (JSON object), each joint's friction from its bearing at
    ``bearing_mu`` if given (its joints rebuilt from the manifest)."""
    from rjcad.physics.finger import model_from_manifest

    model = model_from_manifest(man, mu_t=mu_t)
    if bearing_mu is None:
        return model
    from rjcad.design.rebuild import designs
    from rjcad.io.manifest import Manifest
    from rjcad.physics.bearing_band import with_bearing_friction

    return with_bearing_friction(model, designs(Manifest.coerce(man), "the manifest"), bearing_mu)[0]


def close_grasp(
    man: dict,
    objects: Sequence[Object],
    max_tension_n: float,
    stroke: float | None,
    steps: int,
    mu_t: float = 0.0,
    bearing_mu: float | None = None,
) -> Grasp:
    """rjcad's closure of the built finger ``man`` on ``objects`` with its measured outlines, as
    ``rjcad simulate finger MANIFEST --object …`` runs it (tension ramp to ``max_tension_n`` [N] in ``steps``
    readings, stopped at ``stroke`` [mm] if given; gravity off; ``bearing_mu``: ``finger_model``)."""
    from rjcad.physics.grasp_run import base_outline_of, grasp_outlines_of, run_grasp

    model = finger_model(man, mu_t, bearing_mu)
    outlines = grasp_outlines_of(man, model)
    return run_grasp(
        "rjcad", model, objects, max_tension_n=max_tension_n, stroke=stroke, outlines=outlines, steps=steps,
        base_outline=base_outline_of(man),
    )  # fmt: skip


def finger_page(
    b: Any, files: Mapping[str, bytes | str], objects: Sequence[Object] = (), max_tension_n: float = 10.0
) -> dict[str, str]:
    """finger.html of a built finger ``b`` (``rjcad.cad.build.FingerBuild``) whose files hold its finger.glb:
    the page at ``rjcad view``'s defaults (``rjcad finger --html``); with ``objects`` (a template's
    ``[[object]]`` tables), the closure on them."""
    from rjcad.paper import FINGER
    from rjcad.physics.grasp_run import GRASP_STEPS

    glb = files["finger.glb"]
    assert isinstance(glb, bytes)
    man = b.manifest.to_json()
    grasp = close_grasp(man, objects, max_tension_n, None, GRASP_STEPS) if objects else None
    title = "rjcad finger: finger.json"
    return {"finger.html": viewer_html(man, glb, title, FINGER.stroke, DEFAULT_STEPS, grasp=grasp)}


def write_viewer(
    manifest_path: str | Path,
    out: str | Path,
    stroke: float,
    steps: int,
    mu_t: float = 0.0,
    allow_outside: bool = False,
    *,
    objects: Sequence[Object] = (),
    max_tension_n: float = 10.0,
    grasp_stroke: float | None = None,
    bearing_mu: float | None = None,
) -> Path:
    """Write the page of the built finger ``manifest_path`` to ``out`` atomically; return its path. With
    ``objects``: the closure on them in ``steps`` readings (``close_grasp``), else the pull over ``stroke`` mm;
    ``bearing_mu``: the joints' friction from their bearings (``finger_model``)."""
    from rjcad.io.config import write_atomic

    vendored_three()  # before the simulation: a missing three.js is the first thing to say
    man, glb = read_built(manifest_path, allow_outside)
    title = f"rjcad {man.get('kind', 'finger')}: {Path(manifest_path).name}"
    grasp = close_grasp(man, objects, max_tension_n, grasp_stroke, steps, mu_t, bearing_mu) if objects else None
    return write_atomic(out, viewer_html(man, glb, title, stroke, steps, mu_t, grasp, bearing_mu))
