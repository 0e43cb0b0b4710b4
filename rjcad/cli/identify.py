"""``rjcad bench`` (write a synthetic campaign) and ``rjcad identify`` (find what the design model misses)."""

from __future__ import annotations

import json

import click

from rjcad.cli.options import OutDir
from rjcad.errors import quote
from rjcad.paper import JOINT
from rjcad.progress import report


def _key_values(text: str, option: str) -> dict[str, float]:
    """'a=1,b=2' → {'a': 1.0, 'b': 2.0}; click.BadParameter on bad syntax."""
    out = {}
    for item in (s.strip() for s in text.split(",")):
        if not item:
            continue
        key, eq, value = item.partition("=")
        try:
            if not eq or not key.strip():
                raise ValueError
            out[key.strip()] = float(value)
        except ValueError:
            raise click.BadParameter(f"{quote(item)} is not NAME=NUMBER", param_hint=option) from None
    return out


@click.command()
@click.option(
    "--effects", default="", help="Comma-separated catalogue effects in the true model (none: the null case)."
)
@click.option("--param", "params", multiple=True, help="NAME=VALUE (JSON name, e.g. mu_j_mm=5); repeatable.")
@click.option("--noise", default="", help="Noise σ per column, e.g. torque_nmm=0.1,tendon_force_n=0.02,theta_deg=0.1.")
@click.option("--seed", type=int, default=0, show_default=True, help="Random seed (same seed, same files).")
@click.option("--samples", type=int, default=3000, show_default=True, help="Samples per experiment (>= 100).")
@click.option("--rotation", type=float, default=90.0, show_default=True, help="Joint rotation from rest [deg].")
@click.option(
    "--trajectory",
    type=click.Choice(["paper", "one-speed", "one-speed-holds", "two-speeds"]),
    default="paper",
    show_default=True,
    help="Angle path of every experiment: the paper-like three speeds with holds, or a simpler one.",
)
@click.option(
    "--paper",
    is_flag=True,
    help=f"The paper's campaign: its design and measured parameters, F_n {JOINT.normal_load:g} N in A-C.",
)
@click.option(
    "--finger",
    "finger",
    is_flag=True,
    help="A whole-finger campaign (tendon stroke and joint angles) instead of a joint's.",
)
@click.option(
    "--source",
    type=click.Path(dir_okay=False),
    help="With --finger: the finger manifest (.json) or template (.toml); default: templates/finger.toml.",
)
@click.option("--no-tension", is_flag=True, help="With --finger: no tendon_force_n column (no load cell).")
@click.option(
    "--manifest",
    "joint",
    type=click.Path(dir_okay=False),
    help="A built joint's manifest (rjcad joint's JSON): the campaign names a copy, its design is that joint's, "
    "and its tendon runs load that joint's bearing (effect bearing_friction).",
)
@click.option("--out", "out_dir", type=OutDir(), required=True, help="The campaign folder to write.")
def bench(
    effects, params, noise, seed, samples, rotation, trajectory, paper, finger, source, no_tension, joint, out_dir
):
    """Write a SYNTHETIC campaign simulated from the joint model (experiments A-E of the paper) or, with
    --finger, from the finger model (pull/release records), with noise."""
    from pathlib import Path

    from rjcad.identify.bench import PAPER_PRESET, write_campaign

    overrides = {}
    for p in params:
        overrides.update(_key_values(p, "--param"))
    chosen = [e.strip() for e in effects.split(",") if e.strip()]
    if finger:
        from rjcad.identify.finger.bench import write_finger_campaign

        if paper or joint:
            hint = "--paper" if paper else "--manifest"
            raise click.BadParameter(f"{hint} is a joint campaign's; not with --finger", param_hint=hint)
        truth = write_finger_campaign(
            out_dir,
            chosen,
            overrides,
            finger=source,
            seed=seed,
            noise=_key_values(noise, "--noise"),
            samples=samples,
            tension=not no_tension,
        )
        click.echo(
            f"wrote {Path(out_dir) / 'campaign.toml'} (SYNTHETIC, {len(truth['experiments'])} experiments, "
            f"{samples} samples each, finger {truth['finger']})"
        )
        return
    design = None
    if paper:
        if chosen:
            raise click.BadParameter("give either --paper or --effects", param_hint="--effects")
        chosen, design = list(PAPER_PRESET["effects"]), PAPER_PRESET["design"]
        overrides = {**PAPER_PRESET["params"], **overrides}
    truth = write_campaign(
        out_dir,
        chosen,
        overrides,
        design=design,
        seed=seed,
        noise=_key_values(noise, "--noise"),
        samples=samples,
        rotation_deg=rotation,
        trajectory_name=trajectory,
        joint=joint,
    )
    out = Path(out_dir)
    click.echo(f"wrote {out / 'campaign.toml'}")
    if "joint" in truth:
        click.echo(f"wrote {out / truth['joint']['file']} (the joint's manifest)")
    for e in truth["experiments"]:
        click.echo(f"wrote {out / e['file']} ({samples} samples, {e['quantity']})")
    click.echo(f"wrote {out / 'truth.json'}")
    click.echo(f"wrote {out / 'README.md'}")


@click.command()
@click.argument("campaign", required=False, type=click.Path())
@click.option(
    "--json",
    "json_out",
    is_flag=False,
    flag_value="-",
    default=None,
    metavar="",
    help="Print the result as one JSON object (`--json FILE`, the former form, still writes FILE).",
)
@click.option("--report", "report_dir", type=OutDir(), help="Write report.md and PNG plots here.")
@click.option(
    "--allow-outside",
    is_flag=True,
    help="Read data files outside the campaign file's folder (default: refused, symlinks followed).",
)
def identify(campaign, json_out, report_dir, allow_outside):
    """What the design simulation gets wrong in measured data, which effects cause it, and the gain. CAMPAIGN is
    a campaign TOML or its folder (its campaign.toml)."""
    from pathlib import Path

    from rjcad.cli.options import deprecated
    from rjcad.cli.progress import progress_line
    from rjcad.identify.campaign import load_campaign
    from rjcad.io.config import write_json
    from rjcad.io.outputs import check_writable, refuse_special

    if campaign is None:
        if json_out in (None, "-"):
            raise click.MissingParameter(param_type="argument", param_hint="'CAMPAIGN'")
        campaign, json_out = json_out, "-"  # `identify --json C`: --json took the campaign as its value
    if json_out not in (None, "-"):
        deprecated("--json FILE", "--json (one JSON object on stdout; > FILE to keep it)")
    if json_out not in (None, "-"):  # the former --json FILE (--report is refused by OutDir as it is read)
        refuse_special(json_out)
        check_writable(Path(json_out).parent)  # before the fit, not after it
    with progress_line("identify") as progress:
        report(progress, "reading the campaign")
        camp = load_campaign(campaign, allow_outside=allow_outside)
        js, written = _identified(camp, report_dir, progress)
    if json_out and json_out != "-":
        written.insert(0, str(write_json(json_out, js)))
    if json_out == "-":
        click.echo(json.dumps(js, indent=2))
        return
    print_identification(js)
    for path in written:
        click.echo(f"wrote {path}")


def _identified(camp, report_dir: str | None, progress) -> tuple[dict, list[str]]:
    """The identification's JSON and the report files written (with ``report_dir``), for any kind of campaign."""
    from pathlib import Path

    if getattr(camp, "kind", "joint") == "finger-endpoint":
        from rjcad.identify.finger import endpoint

        assert isinstance(camp, endpoint.EndpointCampaign)
        report(progress, "fitting the endpoint's candidate sets")
        js = endpoint.identify_endpoints(camp)
        written = []
        if report_dir:
            from rjcad.io.outputs import write_set

            write_set(Path(report_dir), {"report.md": endpoint.render_markdown(js)})
            written = [str(Path(report_dir) / "report.md")]
        return js, written
    if getattr(camp, "kind", "joint") == "finger":
        from rjcad.identify.finger import result as finger_result
        from rjcad.identify.finger.data import FingerCampaign
        from rjcad.identify.finger.propose import FingerBasis
        from rjcad.identify.propose import extend

        assert isinstance(camp, FingerCampaign)
        ident, extension = extend(camp, progress=progress, basis=FingerBasis(camp.design.model.n))
        js = finger_result.to_json(ident, extension)
        if report_dir:
            report(progress, "writing the report")
        return js, [str(p) for p in finger_result.write_report(js, report_dir)] if report_dir else []
    from rjcad.identify.data import Campaign
    from rjcad.identify.propose import extend
    from rjcad.identify.report import write_report
    from rjcad.identify.result import to_json

    assert isinstance(camp, Campaign)
    ident, extension = extend(camp, progress=progress)
    js = to_json(ident, extension)
    if report_dir:
        report(progress, "writing the report")
    return js, [str(p) for p in write_report(ident, js, report_dir)] if report_dir else []


def print_identification(js: dict) -> None:
    """The identification (its JSON): notes, effects found, each step, parameters with CIs, each experiment's fit."""
    for note in js["notes"]:
        click.echo(f"note: {note}")
    found = ", ".join(js["effects"]) or "nothing beyond the design simulation"
    click.echo(f"found: {found}  (gain {js['gain']:.3g}x in RMSE, geometric mean over experiments)")
    if js.get("kind") == "finger-endpoint":
        for e in js["experiments"]:
            click.echo(
                f"  {e['file']} at {e['tendon_mm']:g} mm: measured "
                + ", ".join(f"{x:.1f}" for x in e["measured_deg"])
                + " deg; final / noise "
                + ", ".join(f"{x:.2g}" for x in e["final_over_noise"].values())
            )
        for a in js["ambiguous"]:
            click.echo(f"  explains it as well: {', '.join(a['effects'])} ({', '.join(a['params'])})")
        if js["ambiguous"]:
            click.echo(f"  separate them by {js['ambiguous'][0]['separate_by']}")
        for name, value in js["params"].items():
            click.echo(f"  {name} = {value:.4g}")
        return
    for s in js["steps"]:
        ho = "n/a" if s["heldout_rmse"] is None else f"{s['heldout_rmse']:.3g}"
        what = f"{s['effect']} (in the place of {s['replaces']})" if s.get("replaces") else s["effect"]
        click.echo(f"  {s['action']} {what}: dBIC {s['delta_bic']:+.4g}, held-out RMSE {ho} x noise - {s['cause']}")
    for name, value in js["params"].items():
        ci = js["param_ci95"].get(name)
        click.echo(f"  {name} = {value:.4g}" + (f"  [{ci[0]:.4g}, {ci[1]:.4g}]" if ci else "  (design)"))
    for name, why in js["not_identifiable_why"].items():
        click.echo(f"  not identifiable: {name} ({why})")
    if js.get("kind") == "finger":
        from rjcad.identify.finger.result import joint_sentences

        for line in joint_sentences(js):
            click.echo(f"  {line}")
    for a in js.get("ambiguous", []):
        click.echo(
            f"  ambiguous: {', '.join(a['effects'])} (dBIC {a['delta_bic']:+.3g}); separate by {a['separate_by']}"
        )
    if js["proposed"]:
        click.echo("  the fits below are of the data less the proposed term(s) at the end")
    for e in js["experiments"] if js.get("kind") != "finger" else []:
        click.echo(
            f"  {e['file']}: RMSE {e['rmse_design']:.4g} -> {e['rmse_final']:.4g} {e['quantity']} "
            f"(noise {e['noise']:.3g}, {e['samples_masked_at_reversals']} samples at reversals masked)"
        )
    from rjcad.identify.verdict import verdict_sentences

    for line in verdict_sentences(js) if js["unexplained"] else []:
        click.echo(f"  {line}")
    for p in js["proposed"]:
        lo, hi = p["ci95"]
        click.echo(
            f"  proposed, outside the catalogue: {p['words']} ({p['expression']}, c = {p['coefficient']:.4g} "
            f"[{lo:.4g}, {hi:.4g}]; held-out RMSE {p['heldout_rmse_before']:.3g} -> {p['heldout_rmse_after']:.3g} x noise)"
        )
