"""``rjcad life``: the paper's Table I, the stress-only life law, its critique and the extension."""

from __future__ import annotations

import json

import click

from rjcad.cli.options import OutDir, OutFile, print_table


@click.command()
@click.option("--json", "as_json", is_flag=True, help="Print one JSON object.")
@click.option("--plot", type=OutFile(), help="Write the models against the data as a PNG.")
@click.option(
    "--doc", "doc_dir", type=OutDir(), help="Regenerate DOC_DIR/life.md and life.png (every number computed)."
)
@click.option(
    "--sims",
    type=click.IntRange(10, 100000),
    default=200,
    show_default=True,
    help="Bootstrap tables per model for --doc.",
)
def life(as_json, plot, doc_dir, sims):
    """Spring life from the paper's Table I: the stress-only law, what it gets wrong, and the extension."""
    from rjcad import life as lf

    c = lf.critique()
    d = c.to_dict()
    if plot:
        lf.write_plot(c, plot)
    if doc_dir:
        lf.write_doc(c, doc_dir, n_sim=sims)
    if as_json:
        click.echo(json.dumps(d, indent=2))
    else:
        print_critique(d)


def _law(v: dict) -> str:
    return ", ".join(f"{k} = {x:.3g}" for k, x in v["params"].items()) + (
        "" if v["stress_term"] else " (no stress term)"
    )


def print_critique(d: dict) -> None:
    """The critique (``Critique.to_dict()``): each law's fit, the choice, then Table I row by row."""
    b, e = d["baseline"], d["extended"]
    click.echo(f"stress-only law:  {_law(b)}; LOO RMSE {b['loo_rmse_log10']:.3f} log10, AICc {b['aicc']:.2f}")
    for name, v in d["candidates"].items():
        click.echo(f"+ {name:<13} {_law(v)}; LOO RMSE {v['loo_rmse_log10']:.3f}, ΔAICc {v['delta_aicc']:+.2f}")
    chosen = ", ".join(e["effects"]) or "none (the stress-only law stays)"
    click.echo(
        f"chosen: {chosen}; gain {d['gain']:.2f}x (LOO {b['loo_rmse_log10']:.3f} -> "
        f"{e['loo_rmse_log10']:.3f}); Akaike weights "
        + ", ".join(f"{k} {v:.2f}" for k, v in d["akaike_weights"].items())
    )
    print_table(
        [
            (
                f"row {r['row']}",
                f"σa {r['stress_amp_mpa']:5.2f} MPa  observed {r['observed_cycles']:7.2g}"
                f"{'+' if r['censored'] else ' '}  stress-only {r['baseline_cycles']:7.2g} "
                f"(res {r['baseline_residual_log10']:+.2f}, LOO {r['baseline_loo_error_log10']:+.2f})  extended "
                f"{r['extended_cycles']:7.2g} (res {r['extended_residual_log10']:+.2f}, "
                f"LOO {r['extended_loo_error_log10']:+.2f})",
                "",
            )
            for r in d["rows"]
        ]
    )
