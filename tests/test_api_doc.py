"""docs/api.md: every public name of the API is on the page. Its examples run, in order, and print what the page
shows under them, in tests/test_docs_examples.py (as every page's)."""

from __future__ import annotations

import re

import rjcad
from rjcad import api


def test_every_public_name_is_documented(root):
    doc = (root / "docs" / "api.md").read_text(encoding="utf-8")
    names = set(rjcad.__all__) - {"__version__"}
    for cls in (api.Spring, api.Joint, api.Finger, api.Closure, rjcad.CheckReport, rjcad.CheckResult):
        names |= {n for n in dir(cls) if not n.startswith("_")}
    names |= set(api.Closure.__dataclass_fields__)
    missing = sorted(n for n in names if not re.search(rf"\b{re.escape(n)}\b", doc))
    assert not missing, missing
    assert "__version__" in doc
