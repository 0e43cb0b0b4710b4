"""Whether an identification explains its data: the final residual of each measured quantity against its noise
floor, said in the same words (and the same JSON keys) for a joint and for a finger.

A quantity is explained when its final RMSE / noise σ ≤ FLOOR_RATIO. Anything above is a residual the accepted
effects do not explain: the answer then says so, marks the accepted effects ``partial``, and with no effect
accepted says that the design model misses something the catalogue does not hold (never "nothing was needed").
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from rjcad.identify.formatting import fmt

#: final RMSE / noise σ up to which a quantity counts as explained to the noise floor (a fit to the noise itself
#: gives 1.0 within a few % on the thousands of samples of an experiment; 1.2 leaves room for a noise σ that is
#: itself estimated from the data)
FLOOR_RATIO = 1.2

#: The answer when nothing was accepted and nothing is left above the noise.
NOTHING_NEEDED = "Nothing beyond the design model was needed: it explains the data to the noise floor."
#: The answer when nothing was accepted and a residual is left.
OUTSIDE_CATALOGUE = "The design model misses something the catalogue does not hold."


def verdict_json(over_noise: Mapping[str, float | None], effects: Sequence[str]) -> dict[str, Any]:
    """``unexplained`` (any quantity above FLOOR_RATIO), ``unexplained_over_noise`` {quantity: final RMSE / noise}
    of those, and ``partial``: the accepted effects, each explaining only part of the data, when unexplained."""
    above = {k: v for k, v in over_noise.items() if v is not None and v > FLOOR_RATIO}
    return {"unexplained": bool(above), "unexplained_over_noise": above, "partial": list(effects) if above else []}


def verdict_sentences(js: Mapping[str, Any]) -> list[str]:
    """The report's words for a result's verdict keys (``verdict_json``): one line, or two with nothing accepted."""
    above = js["unexplained_over_noise"]
    if not above:
        return [NOTHING_NEEDED] if not js["effects"] else []
    where = ", ".join(f"{k} ({fmt(v, 3)}× noise)" for k, v in above.items())
    verb = "stays" if len(above) == 1 else "stay"
    line = f"The residual is not explained: {where} {verb} above the noise floor ({FLOOR_RATIO:g}× noise)."
    if js["effects"]:
        named = ", ".join(f"`{e}`" for e in js["partial"])
        return [line + f" The accepted effects ({named}) explain only part of the data: partial."]
    return [line, OUTSIDE_CATALOGUE]
