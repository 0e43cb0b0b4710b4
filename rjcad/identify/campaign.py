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


#: The campaign file in a campaign folder (``rjcad bench`` writes it; ``rjcad identify DIR`` reads it).
CAMPAIGN_FILE = "campaign.toml"


def campaign_file(path: str | Path) -> Path:
    """The campaign TOML ``path`` names: the file itself, or a folder's ``campaign.toml``."""
    path = Path(path)
    if not path.is_dir():
        return path
    inside = path / CAMPAIGN_FILE
    if not inside.is_file():
        from rjcad.errors import BadInput

        raise BadInput(f"{path}: a folder with no {CAMPAIGN_FILE} file in it (give the campaign file or its folder)")
    return inside


def load_campaign(path: str | Path, allow_outside: bool = False) -> Campaign | FingerCampaign | EndpointCampaign:
    """Read and validate a campaign TOML and its files (one error line naming the file on bad input); ``path``
    may be the campaign's folder (its ``campaign.toml``)."""
    path = campaign_file(path)
    doc = read_toml(path)
    if is_finger_campaign(doc):
        if "endpoint" in doc:
            from rjcad.identify.finger.endpoint import load_endpoint_campaign

            return load_endpoint_campaign(path, doc, allow_outside)
        return load_finger_campaign(path, doc, allow_outside)
    return load_joint_campaign(path, allow_outside, doc=doc)
