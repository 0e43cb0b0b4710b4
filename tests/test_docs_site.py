"""The user guide builds as a web site (mkdocs.yml, `make docs`) with warnings as errors: every page in the nav,
every link and anchor found. Built in-process (about a second)."""

from __future__ import annotations

import contextlib
import logging

import pytest


def test_the_site_builds_without_a_warning(root, tmp_path, monkeypatch):
    pytest.importorskip("mkdocs", reason="mkdocs is not installed (pip install -e '.[docs]')")
    pytest.importorskip("material", reason="mkdocs-material is not installed (pip install -e '.[docs]')")
    from mkdocs.commands.build import build as build_site  # (not `build`: tests/conftest.py reads that as CAD)
    from mkdocs.config import load_config
    from mkdocs.exceptions import Abort

    monkeypatch.setenv("NO_MKDOCS_2_WARNING", "1")  # Material's notice about its successor
    warnings: list[str] = []
    handler = logging.Handler(logging.WARNING)
    handler.emit = lambda record: warnings.append(record.getMessage())  # type: ignore[method-assign]
    logger = logging.getLogger("mkdocs")
    logger.addHandler(handler)
    try:
        config = load_config(str(root / "mkdocs.yml"), strict=True, site_dir=str(tmp_path / "site"))
        with contextlib.suppress(Abort):  # strict mode's "Aborted with N warnings": the warnings are listed below
            build_site(config)
    finally:
        logger.removeHandler(handler)
    assert not warnings, "\n".join(warnings)
    assert (tmp_path / "site" / "index.html").is_file()
