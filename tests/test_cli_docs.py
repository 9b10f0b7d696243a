"""``masonry docs`` and the pages messages send the user to. Messages, --help texts and recordings named
``docs/collapse.md``, ``docs/sweep.md``, ``docs/scenario-format.md`` and the README: files of a clone,
absent from an install made from a wheel. They now name a topic (``masonry docs collapse``), and the wheel
carries the pages (setup.py, MANIFEST.in)."""

from __future__ import annotations

import ast
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from masonrycli.cli import docs as user_docs

from cli_helpers import assert_one_line_error, invoke, words

ROOT = Path(__file__).resolve().parent.parent
TOPIC = re.compile(r"masonry docs ([a-z][a-z0-9-]*)")


def _user_facing_strings() -> list[tuple[str, int, str]]:
    """Every string constant of masonrycli/ and geometry_library/ but docstrings and other bare string
    statements: the messages, help texts and recorded text a user reads."""
    found = []
    for path in sorted((ROOT / "masonrycli").rglob("*.py")) + sorted((ROOT / "geometry_library").rglob("*.py")):
        tree = ast.parse(path.read_text())
        bare = {id(n.value) for n in ast.walk(tree) if isinstance(n, ast.Expr) and isinstance(n.value, ast.Constant)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in bare:
                found.append((str(path.relative_to(ROOT)), node.lineno, node.value))
    return found


def _named_topics() -> set[str]:
    return {topic for *_, text in _user_facing_strings() for topic in TOPIC.findall(text)}


def test_messages_name_topics_not_files_of_the_clone():
    # before: builtin.py "(docs/scenario-format.md)", cli_options.py "(docs/collapse.md)", recording/study.py
    # "(docs/sweep.md)", history_inspect.py "(README, 'What a run writes', …)": nowhere in an install
    clone_only = [
        (file, line, text)
        for file, line, text in _user_facing_strings()
        # a page's name (x.md), not a bare suffix: study/plan.py lists ".md" among the files a records folder may hold
        if re.search(r"docs/|\w\.md\b|README", text) and file != "masonrycli/cli/docs.py"  # where the pages are
    ]
    assert clone_only == []
    assert {"collapse", "sweep", "scenario-format", "readme"} <= _named_topics()


def test_every_topic_a_message_names_is_a_page():
    topics = {page.topic for page in user_docs.pages()}
    assert _named_topics() <= topics
    assert {p.stem for p in (ROOT / "docs").glob("*.md")} | {"readme"} == topics


def test_docs_lists_the_topics_and_prints_a_page_or_its_file():
    result = invoke("docs")
    assert result.exit_code == 0, result.output
    assert "collapse Collapse, damage and intact: what a run reports about the structure" in words(result.output)
    assert "masonry docs TOPIC prints one" in result.output
    result = invoke("docs", "sweep")
    assert result.exit_code == 0 and result.output == (ROOT / "docs" / "sweep.md").read_text()
    for spelling in ("collapse", "Collapse", "collapse.md", "docs/collapse.md"):
        result = invoke("docs", spelling, "--path")
        assert result.exit_code == 0 and result.output == f"{ROOT / 'docs' / 'collapse.md'}\n"
    assert invoke("docs", "readme", "--path").output == f"{ROOT / 'README.md'}\n"


def test_an_unknown_topic_is_one_line_naming_the_topics():
    assert_one_line_error(invoke("docs", "colapse"), "docs: no topic 'colapse'; the topics: readme,", "sweep")


def _copy_sources(target: Path) -> None:
    """What an sdist is made of (a copy: building writes masonry.egg-info beside the sources)."""
    target.mkdir()
    for name in ("pyproject.toml", "setup.py", "MANIFEST.in", "README.md"):
        shutil.copy(ROOT / name, target / name)
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "images")
    for name in ("masonrycli", "geometry_library", "docs"):
        shutil.copytree(ROOT / name, target / name, ignore=ignore)


@pytest.mark.slow
def test_an_install_from_a_wheel_has_every_page_a_message_names(tmp_path):
    # As `python -m build` makes it: the sdist, then the wheel from the unpacked sdist (pip builds it in an
    # isolated environment, as build does). Before, the wheel held no page and masonry had no docs command.
    source, dist = tmp_path / "source", tmp_path / "dist"
    _copy_sources(source)
    make_sdist = f"from setuptools import build_meta; print(build_meta.build_sdist({str(dist)!r}))"
    done = subprocess.run([sys.executable, "-c", make_sdist], cwd=source, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    sdist = dist / done.stdout.split()[-1]
    wheel_cmd = [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-cache-dir", "-q", "-w", dist, sdist]
    done = subprocess.run(wheel_cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    (wheel,) = dist.glob("masonry-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        shipped = {Path(n).name for n in archive.namelist() if n.startswith("masonrycli/docs/")}
    assert shipped == {p.name for p in (ROOT / "docs").glob("*.md")} | {"README.md"}

    # a fresh venv holding the wheel alone; masonry's dependencies come from this one through a path file
    # (added after the install, so pip never sees this venv's masonry)
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", venv], check=True)
    # without PYTHONPATH: a worktree's on it finds the clone's masonry.egg-info, and pip installs nothing
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"} | {"RERUN_ANALYTICS": "0"}
    install = [sys.executable, "-m", "pip", "--python", venv / "bin" / "python", "install", "-q", "--no-deps"]
    subprocess.run([*install, "--no-index", "--no-cache-dir", wheel], check=True, capture_output=True, env=env)
    site = subprocess.run(
        [venv / "bin" / "python", "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True, text=True, check=True,
    ).stdout.strip()  # fmt: skip
    Path(site, "dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()

    def masonry(*args):
        done = subprocess.run([venv / "bin" / "masonry", *args], cwd=elsewhere, env=env, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done.stdout

    assert f"The pages are Markdown files in {site}/masonrycli/docs." in words(masonry("docs"))
    for topic in _named_topics() | {"limit"}:
        path = Path(masonry("docs", topic, "--path").strip())
        assert path.is_relative_to(site) and path.is_file(), path
        shown = masonry("docs", topic)
        assert shown == (ROOT / ("README.md" if topic == "readme" else f"docs/{topic}.md")).read_text()
    assert "(masonry docs collapse)" in words(masonry("run", "--help"))
