"""Packaging hook; everything else is in pyproject.toml. The wheel carries the documentation pages (docs/*.md
and README.md) as masonrycli/docs/, so ``masonry docs`` and the messages that name a topic work in an
install without the clone (masonrycli/cli/docs.py). MANIFEST.in puts the pages in the sdist, which
``python -m build`` makes the wheel from. An editable install reads them from the clone instead."""

from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent


class BuildWithDocs(build_py):
    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):
            return
        target = Path(self.build_lib, "masonrycli", "docs")
        self.mkpath(str(target))
        for page in [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]:
            self.copy_file(str(page), str(target / page.name))


setup(cmdclass={"build_py": BuildWithDocs})
