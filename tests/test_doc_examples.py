"""Every command line the documentation and the --help texts show, as a student copies it.

Each example is parsed by the command it names (its options exist, its values convert: an option renamed
in the code and not in a page fails here), and the examples of the pages' code blocks, and the inline ones
that name files we can make, are run, in a folder holding the files they name: a scenario file, a GeoJSON,
an .AT2 record, a records folder. Run short: every ``simulate``, ``run`` and ``sweep`` gets ``--duration
0.05`` (its own replaced), and a sweep ``--workers 0`` (in this process; ``--scheduler`` dropped); the
whole-length runs are the paper scenarios' own tests. What is not run is in ``NOT_RUN`` with the reason,
and every entry there must still be an example (a stale one fails).
"""

from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import click
import numpy as np
import pytest
import surveyed_wall
import traced_bridge
import typer

from masonrycli.cli.app import app

from cli_helpers import invoke
from synthetic_records import band_limited, write_at2

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
COMMAND = re.compile(r"(?:\.venv/bin/)?masonry (.*)")
PLACEHOLDER = re.compile(r"…|\.\.\.|\\\||\[-|\b[A-Z]+\.\w+\b|\b(?:SCENARIO|FILE|FOLDER|DIR|TOPIC|COMMAND|NAME)\b")
FRAGMENTS = {  # in a sentence, not a command line
    "sweep --find amp --outcome sliding",  # collapse.md: the option, named
    "build wall",  # README: "the same 51-block wall (`masonry build wall`)", the builder named
    "build arch",  # limit.md: "the segmental arch that `masonry build arch` writes with those options"
}
NOT_RUN = {  # example -> why it is parsed only
    "check traced-wall.geojson": "refused on purpose: the page shows its refusals (test_cli_survey)",
    "export h.npz --times lab.csv --compare 'LVDT top (mm)' --out lab-vs-masonry.csv": "a laboratory's measurements",
    "docs collapse": "prints a page: test_user_docs",
    "limit aqueduct --verify": "30 s, run with --out mech.rrd on the same page",
    "build arch --help": "help: test_every_help_example_parses",
    "inspect study.csv": "needs a study written first: test_study_table",
    "export h/ --top": "the README's history folder: test_history_export",
    "export h/ --combined": "the README's history folder: test_history_export",
    "export h --combined": "the README's history folder: test_history_export",
    "export h.npz --blocks c06-b05 --course 3 --top": "the README's h.npz: test_history_export",
    "export h.npz --blocks v08,v15 --top": "limit.md's h.npz, of a run written as 'simulate arch …'",
}


def _pages_examples() -> list[tuple[str, str]]:
    """(page, the command after 'masonry ') of every code-block line and every whole inline command."""
    found = []
    for page in PAGES:
        text = page.read_text()
        for block in re.findall(r"```[a-z]*\n(.*?)```", text, re.S):
            for line in block.replace("\\\n", " ").splitlines():
                if m := COMMAND.match(line.strip()):
                    found.append((page.name, m.group(1)))
        for inline in re.findall(r"`((?:\.venv/bin/)?masonry [^`]+)`", text):
            found.append((page.name, COMMAND.match(" ".join(inline.split())).group(1)))
    examples = []
    for page, command in found:
        command = re.split(r"\s+#|\s+\\?\|\s", command)[0].strip()  # a comment, a pipe into head or grep
        if len(command.split()) >= 2 and not PLACEHOLDER.search(command) and command not in FRAGMENTS:
            examples.append((page, shlex.join(shlex.split(command))))
    return list(dict.fromkeys(examples))


def _help_examples() -> list[tuple[str, str]]:
    """The command lines of the --help texts: as they show them in bold (a sentence's full stop after one is
    not part of it), or a line of their own."""
    group = typer.main.get_command(app)
    found = []
    for name, command in group.commands.items():
        text = command.help or ""
        lines = [m.group(1) for line in text.splitlines() if (m := COMMAND.match(line.strip()))]
        bold = re.findall(r"\[bold\]masonry ([^\[]+)\[/bold\]", text)
        for example in bold or lines:
            if not PLACEHOLDER.search(example):
                found.append((f"masonry {name} --help", example))
    return found


def _parse(command: str) -> None:
    group = typer.main.get_command(app)
    name, *rest = shlex.split(command)
    sub = group.get_command(click.Context(group, info_name="masonry"), name)
    assert sub is not None, f"no command {name!r}"
    try:
        sub.make_context(name, rest, parent=click.Context(group, info_name="masonry"))
    except click.exceptions.Exit:  # --help
        pass


def test_the_examples_are_found():
    examples = dict.fromkeys(command for _, command in _pages_examples())
    assert len(examples) > 60
    assert "simulate wall --freq 2 --amp 1" in examples  # README's quick start
    assert "sweep block.toml --param amp=0.05:1.0:3 --find amp --outcome sliding --out slide.csv" in examples
    assert "limit aqueduct --json" in examples  # the pipe into head cut
    assert set(NOT_RUN) <= set(examples)
    assert any("sweep" in where for where, _ in _help_examples())


@pytest.mark.parametrize("page, command", _pages_examples() + _help_examples())
def test_every_example_parses(page, command):
    _parse(command)


# ------------------------------------------------------------------------------------------- running them

BLOCK_TOML = """[run]
duration = 1.0
dt = 1e-3

[[block]]
name = "b1"
polygon = [[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]]

[[support]]
name = "ground"
polygon = [[-5.0, -0.5], [5.0, -0.5], [5.0, 0.0], [-5.0, 0.0]]
motion = { kind = "sine", direction = [1.0, 0.0], amplitude = 1.0, frequency = 2.0 }
"""


def _pages_files() -> dict[str, str]:
    """The files a page tells the reader to save: a ```toml block after a paragraph saying "save `NAME.toml`"."""
    files = {}
    for page in PAGES:
        for before, text in re.findall(r"((?:[^\n]+\n)+)\n```toml\n(.*?)```", page.read_text(), re.S):
            if named := re.search(r"[Ss]ave (?:this as )?`([\w.-]+\.toml)`", before):
                files[named.group(1)] = text
    return files


def test_the_files_a_page_says_to_save_are_valid_scenarios(tmp_path):
    files = _pages_files()
    assert {"block.toml", "slender.toml"} <= set(files)  # class.md
    for name, text in files.items():
        (tmp_path / name).write_text(text)
        result = invoke("check", tmp_path / name)
        assert result.exit_code == 0, f"{name}: {result.output}"


def _seed(folder: Path) -> None:
    """The files the examples name, in ``folder``."""
    for name in ("block.toml", "wall.toml", "rubble.toml"):
        (folder / name).write_text(BLOCK_TOML)
    for name, text in _pages_files().items():  # "Save this as `block.toml`:" and its TOML (class.md)
        (folder / name).write_text(text)
    (folder / "my-arch.toml").write_text((ROOT / "tests" / "data" / "arch_settlement.toml").read_text())
    for name, structure in (("wall", "wall"), ("my-wall", "wall"), ("rubble", "wall"), ("arch", "arch")):
        assert invoke("build", structure, "--out", folder / f"{name}.geojson").exit_code == 0
    # limit.md's b.geojson: the filled bridge as 'masonry build arch … --fill-cover 0.3 --out b.geojson' writes it
    bridge = ("--span", 8, "--rise", 2, "--ring-thickness", 0.5, "--pier-width", 3, "--pier-courses", 5)
    assert invoke("build", "arch", *bridge, "--fill-cover", 0.3, "--out", folder / "b.geojson").exit_code == 0
    t, _, v, a = band_limited(1.0, 0.01, [1.0, 2.5], [0.01, 0.004])
    np.savetxt(folder / "table.csv", np.column_stack([t, v]), delimiter=",", header="time (s),vel (m/s)", comments="")
    write_at2(folder / "quake.AT2", a / 9.81, 0.01)
    for records in ("records", "recs"):
        (folder / records).mkdir()
        write_at2(folder / records / "RSN6_IMPVALL.I_I-ELC180.AT2", a / 9.81, 0.01)
    write_at2(folder / "recs" / "RSN900_SYN-0.AT2", a / 9.81, 0.01)  # sweep.md's fragility study, a row replayed
    (folder / "frag.csv").write_text(  # and its table, read by the page's Python (two rows a study makes)
        "record,blocks,pga_g,friction,state,peak_drift,status,error,study,source,command\n"
        "RSN900_SYN-0.AT2,12,2.25,0.5,collapsed,0.25,completed,,abc,def,masonry sweep …\n"
        "RSN900_SYN-0.AT2,12,2.25,0.6,damaged,0.12,completed,,abc,def,masonry sweep …\n"
    )
    arch = json.loads((folder / "arch.geojson").read_text())  # scenario-format.md: "those marked driven shake"
    for feature in arch["features"]:
        if feature["properties"]["role"] == "support":
            feature["properties"]["support_role"] = "driven"
    (folder / "arch.geojson").write_text(json.dumps(arch))
    (folder / "my wall.toml").write_text(BLOCK_TOML)  # class.md: a name with a space, between quotes
    # scenario-format.md: a wall traced in QGIS (Lambert-93, mm slips, 4 stones dented)
    surveyed_wall.write(folder / "traced-wall.geojson", offset=surveyed_wall.LAMBERT93, dent=2e-3, dents=4)
    # README's and scenario-format.md's bridge.geojson: a rubble bridge traced in Lambert-93 to the mm, with its fill
    traced_bridge.write(folder / "bridge.geojson", offset=surveyed_wall.LAMBERT93, ndigits=3)
    (folder / "recordings").mkdir()  # made by README's quick start, before its other examples


def _short(command: str) -> list[str]:
    words = shlex.split(command)
    if words[0] in ("simulate", "run", "sweep"):
        for option in ("--duration", "--scheduler"):
            while option in words:
                at = words.index(option)
                del words[at : at + 2]
        words += ["--duration", "0.05"]
    if words[0] == "sweep" and "--workers" not in words:
        words += ["--workers", "0"]
    return words


def _runnable():
    by_page: dict[str, list[str]] = {}
    for page, command in _pages_examples():
        if command not in NOT_RUN:
            by_page.setdefault(page, []).append(command)
    return sorted(by_page.items())


@pytest.mark.slow
@pytest.mark.parametrize("page, commands", _runnable())
def test_the_pages_examples_run(page, commands, tmp_path, monkeypatch):
    _seed(tmp_path)
    monkeypatch.chdir(tmp_path)
    failed = []
    for command in commands:
        words = _short(command)
        # a page's examples write the same outputs (scenarios.md gives each command twice, sweep.md's default
        # study-wall.*): they are refused, not overwritten, unless --force — a student runs one, then the next
        outputs = [Path(words[at + 1]) for at, word in enumerate(words) if word in ("--out", "--history")]
        beside = [out.with_suffix(suffix) for out in outputs for suffix in (".png", ".rrd")]  # a sweep's plot
        for target in outputs + beside + list(tmp_path.glob("study-*")):
            if target.is_file():
                target.unlink()
        if "--record-dt" in words:  # its folder is of one-value CSVs (sweep.md), which the others refuse
            one_column = Path(words[words.index("--records") + 1]) / "one-column.csv"
            np.savetxt(one_column, np.sin(np.linspace(0, 6, 101)) * 0.01)
        result = invoke(*words)
        if "--record-dt" in words:
            one_column.unlink()
        if result.exit_code != 0:
            failed.append(f"masonry {command}: exit {result.exit_code}: {result.output.strip()[-400:]}")
    assert not failed, "\n".join(failed)


def _python_blocks() -> list[tuple[str, int, str]]:
    """(page, number, code) of the ```python blocks of every page but docs/python.md (test_api runs that one as a
    notebook): README's first steps from Python, scenario-format.md's loading and building."""
    found = []
    for page in PAGES:
        if page.name != "python.md":
            for k, code in enumerate(re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S)):
                found.append((page.name, k + 1, code))
    return found


def test_the_python_blocks_are_found():
    pages = {page for page, _, _ in _python_blocks()}
    assert {"README.md", "scenario-format.md"} <= pages


@pytest.mark.parametrize("page, number, code", _python_blocks(), ids=lambda v: str(v)[:20])
def test_the_pages_python_blocks_run(page, number, code, tmp_path, monkeypatch):
    # each as a reader pastes it into a notebook, in a folder holding the files it names (wall.toml); only their
    # imports were checked (test_docs), so a block whose call or keyword had changed still 'passed'
    _seed(tmp_path)
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    exec(compile(code, f"{page} python block {number}", "exec"), namespace)
    if "dump_scenario" in code:  # 'TOML text that loads back to the same scenario': written again, the same text
        (tmp_path / "again.toml").write_text(namespace["text"])
        again = namespace["dump_scenario"](namespace["load_scenario"](tmp_path / "again.toml"))
        assert _but_source(again) == _but_source(namespace["text"]) and "[[block]]" in again


def _but_source(text: str) -> str:
    """A dumped scenario without its '# from FILE' line (the file it was read from)."""
    return "\n".join(line for line in text.splitlines() if not line.startswith("# from "))
