"""Any campaign: a joint's (rjcad.identify.data) or a whole finger's (rjcad.identify.finger.data), told apart
by the experiments' drive (a top-level ``finger`` key or ``drive = "finger"``)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from rjcad.identify.data import Campaign, is_finger_campaign
from rjcad.identify.data import load_campaign as load_joint_campaign
from rjcad.identify.finger.data import FingerCampaign, load_finger_campaign
from rjcad.io.untrusted import read_toml

if TYPE_CHECKING:
    from rjcad.identify.finger.endpoint import EndpointCampaign


def load_campaign(path: str | Path, allow_outside: bool = False) -> Campaign | FingerCampaign | EndpointCampaign:
    """Read and validate a campaign TOML and its files (one error line naming the file on bad input)."""
    path = Path(path)
    doc = read_toml(path)
    if is_finger_campaign(doc):
        if "endpoint" in doc:
            from rjcad.identify.finger.endpoint import load_endpoint_campaign

            return load_endpoint_campaign(path, doc, allow_outside)
        return load_finger_campaign(path, doc, allow_outside)
    return load_joint_campaign(path, allow_outside, doc=doc)
