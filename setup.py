"""Build hook: a wheel or an sdist of rjcad carries three.js (tools/vendor_three.py fetches it, pinned)."""

import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

sys.path.insert(0, str(Path(__file__).resolve().parent / "tools"))
from vendor_three import DEFAULT_DEST, fetch  # noqa: E402


class BuildPy(build_py):
    def run(self):
        fetch(DEFAULT_DEST)
        super().run()


class Sdist(sdist):
    def run(self):
        fetch(DEFAULT_DEST)
        super().run()


setup(cmdclass={"build_py": BuildPy, "sdist": Sdist})
