"""``masonry docs``: the documentation pages, wherever masonry is installed.

Messages, ``--help`` texts and recordings send the user to a page by its topic (``masonry docs collapse``),
never by a path: ``docs/collapse.md`` exists in a clone only, and an install from a wheel (``python -m
build``, ``pip install dist/*.whl``, run from another folder) had no docs/ folder at all. The wheel now
carries the pages as package data, ``masonrycli/docs/`` (setup.py copies docs/*.md and README.md there);
a clone (``pip install -e .``) reads them from its own docs/ folder and README.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from masonrycli.errors import InputError

_PACKAGE = Path(__file__).resolve().parent.parent  # masonrycli/, where the wheel puts docs/
README_TOPIC = "readme"


@dataclass(frozen=True)
class Page:
    topic: str
    path: Path

    def title(self) -> str:
        if self.topic == README_TOPIC:
            return "the overview: commands, outputs and overwriting, performance, troubleshooting"
        for line in self.path.read_text(encoding="utf-8").splitlines():
            if line.startswith("# "):
                return line[2:].strip()
        return self.topic


def pages() -> list[Page]:
    """Every page, the README first: the installed copies (``masonrycli/docs/``), else the clone's."""
    installed = _PACKAGE / "docs"
    if installed.is_dir():
        folder, readme = installed, installed / "README.md"
    else:
        folder, readme = _PACKAGE.parent / "docs", _PACKAGE.parent / "README.md"
    found = [Page(README_TOPIC, readme)] if readme.is_file() else []
    return found + [Page(p.stem, p) for p in sorted(folder.glob("*.md")) if p.name != "README.md"]


def topic_name(text: str) -> str:
    """``collapse``, ``Collapse``, ``collapse.md`` and ``docs/collapse.md`` all name one topic."""
    name = text.strip().lower().removeprefix("docs/")
    return name.removesuffix(".md")


def find(topic: str) -> Page:
    """The page of ``topic``; unknown: an InputError that lists the topics."""
    known = pages()
    if not known:
        raise InputError(f"no documentation pages beside {_PACKAGE} (an install without its package data)")
    for page in known:
        if page.topic == topic_name(topic):
            return page
    raise InputError(f"docs: no topic {topic!r}; the topics: {', '.join(p.topic for p in known)}")


def listing() -> list[str]:
    """The lines ``masonry docs`` prints: one per topic, then where the pages are and how to read one."""
    known = pages()
    if not known:
        raise InputError(f"no documentation pages beside {_PACKAGE} (an install without its package data)")
    width = max(len(p.topic) for p in known)
    lines = [f"  {p.topic:<{width}}  {p.title()}" for p in known]
    folders = sorted({str(p.path.parent) for p in known})
    return [
        "Topics:",
        *lines,
        "",
        f"The pages are Markdown files in {' and '.join(folders)}.",
        "masonry docs TOPIC prints one; masonry docs TOPIC --path gives its file.",
    ]
