"""Fetch three.js (the HTML viewer's renderer) from the npm registry into ``rjcad/data/vendor/``.

three.js is not kept in the repository: it is another project's code. It is fetched once, pinned by version
and by the registry's own sha512 integrity, from the package tarball (no npm needed), and its MIT licence is
kept beside it. ``setup.py`` calls this when a wheel or an sdist is built, so an installed rjcad has it;
``make vendor`` calls it for a development checkout.

    python tools/vendor_three.py [DEST_DIR]
"""

from __future__ import annotations

import base64
import hashlib
import io
import sys
import tarfile
import urllib.request
from pathlib import Path

VERSION = "0.170.0"
URL = f"https://registry.npmjs.org/three/-/three-{VERSION}.tgz"
#: The registry's ``dist.integrity`` of that tarball.
INTEGRITY = "sha512-FQK+LEpYc0fBD+J8g6oSEyyNzjp+Q7Ks1C568WWaoMRLW+TkNNWmenWeGgJjV105Gd+p/2ql1ZcjYvNiPZBhuQ=="
#: tarball member → file written in the destination.
FILES = {"package/build/three.module.min.js": "three.module.min.js", "package/LICENSE": "three.LICENSE"}
DEFAULT_DEST = Path(__file__).resolve().parents[1] / "rjcad" / "data" / "vendor"


def present(dest: Path) -> bool:
    """True if ``dest`` holds both files, the module of this VERSION."""
    module = dest / "three.module.min.js"
    if not all((dest / f).is_file() for f in FILES.values()):
        return False
    head = module.read_bytes()[:400].decode("utf-8", "replace")
    return f'const t="{VERSION.split(".")[1]}"' in head


def fetch(dest: Path = DEFAULT_DEST, timeout: float = 120.0) -> None:
    """Download the tarball, check its integrity, write FILES into ``dest`` (each whole: a temporary file renamed)."""
    if present(dest):
        return
    with urllib.request.urlopen(URL, timeout=timeout) as r:
        raw = r.read()
    digest = "sha512-" + base64.b64encode(hashlib.sha512(raw).digest()).decode("ascii")
    if digest != INTEGRITY:
        raise SystemExit(f"three.js {VERSION}: the tarball's sha512 is not the registry's pinned one ({URL})")
    dest.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(raw), mode="r:gz") as tar:
        for member, name in FILES.items():
            f = tar.extractfile(member)
            if f is None:
                raise SystemExit(f"three.js {VERSION}: {member} is not in the tarball")
            tmp = dest / f".{name}.tmp"
            tmp.write_bytes(f.read())
            tmp.replace(dest / name)


if __name__ == "__main__":
    fetch(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_DEST)
