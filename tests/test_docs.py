"""The documentation stays true to the code: every import in a Python example of docs/ and the README
names something that exists where the example says (docs/scenario-format.md once imported
``dump_scenario`` from the wrong module), and the README's layout and docs/architecture.md list every
module of masonrycli/ and geometry_library/ (six were missing once)."""

from __future__ import annotations

import ast
import importlib
import importlib.util
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]


def python_examples(page: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", page.read_text(), flags=re.S)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_imports_in_python_examples_exist(page):
    for code in python_examples(page):
        for node in ast.walk(ast.parse(code)):
            if isinstance(node, ast.ImportFrom) and node.module:
                module = importlib.import_module(node.module)
                for alias in node.names:  # a name, or a submodule ("from masonrycli import api")
                    found = hasattr(module, alias.name) or (
                        hasattr(module, "__path__") and importlib.util.find_spec(f"{node.module}.{alias.name}")
                    )
                    assert found, f"{page.name}: {node.module} has no {alias.name}"
            elif isinstance(node, ast.Import):
                for alias in node.names:
                    importlib.import_module(alias.name)


def test_the_examples_are_found():
    # The pattern above must see the scenario-format examples, or the test would check nothing.
    assert len(python_examples(ROOT / "docs" / "scenario-format.md")) >= 1


def _modules() -> list[Path]:
    found = sorted((ROOT / "masonrycli").rglob("*.py")) + sorted((ROOT / "geometry_library").rglob("*.py"))
    return [p for p in found if p.name != "__init__.py"]


def _code_block(text: str, start: str) -> str:
    """The first fenced block after the heading ``start``."""
    return re.search(r"```.*?\n(.*?)```", text[text.index(start) :], flags=re.S).group(1)


@pytest.mark.parametrize(
    "page, section",
    [("docs/architecture.md", "# Architecture"), ("README.md", "## Layout")],
    ids=["architecture", "readme"],
)
def test_every_module_is_listed(page, section):
    listing = _code_block((ROOT / page).read_text(), section)
    words = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", listing))
    modules = _modules()
    assert len(modules) > 40  # the search above found the packages
    missing = [str(p.relative_to(ROOT)) for p in modules if p.stem not in words]
    assert not missing, f"{page} ({section}) does not list: {', '.join(missing)}"


def test_readme_history_table_names_every_array(tmp_path):
    # Four arrays (the principal strains and their directions) were written but not in the table.
    import numpy as np

    from cli_helpers import invoke

    # The five intensity_* arrays (written only when a support shakes) were not in it either: a shaken run.
    npz = tmp_path / "h.npz"
    args = ("run", ROOT / "tests" / "data" / "quake_record.toml", "--duration", 0.01, "--no-recording")
    assert invoke(*args, "--history", npz).exit_code == 0
    text = (ROOT / "README.md").read_text()
    table = text[text.index("**The history**") : text.index("## Troubleshooting")]
    documented = set(re.findall(r"`([a-z_0-9]+)`", table))
    written = set(np.load(npz).files)
    assert "intensity_pga" in written and written <= documented, sorted(written - documented)


def _table_keys(text: str, heading: str) -> set[str]:
    """The backquoted names in the first column of the table under ``heading`` (up to the next heading)."""
    section = text[text.index(heading) :].split("\n#", 1)[0]
    return set(re.findall(r"^\| `([a-z_]+)`", section, flags=re.M))


def test_scenario_format_tables_list_every_key_the_reader_takes():
    # `[run] solver` was read (README: `[run] solver = "nlgs"`) but missing from the [run] table.
    import dataclasses

    from masonrycli.scenario.scenario import Material, RunConfig
    from masonrycli.scenario.toml_bodies import BLOCK_KEYS, SUPPORT_KEYS

    text = (ROOT / "docs" / "scenario-format.md").read_text()
    assert _table_keys(text, "## `[run]`") == {f.name for f in dataclasses.fields(RunConfig)}
    assert _table_keys(text, "## `[material]`") == {f.name for f in dataclasses.fields(Material)}
    assert _table_keys(text, "## `[[block]]`") == set(BLOCK_KEYS)
    assert _table_keys(text, "## `[[support]]`") == set(SUPPORT_KEYS)


def test_setting_units_are_the_documented_ones():
    """The unit a "1 s"-style message names (geometry_library.values.SETTING_UNITS) is the one the scenario
    format's tables give the key: each table row of a key with a unit names that unit, and a row of a key
    without one names none of the units."""
    from geometry_library.values import SETTING_UNITS

    text = (ROOT / "docs" / "scenario-format.md").read_text()
    rows = {}
    for heading in ("## `[run]`", "## `[material]`", "## `[[block]]`"):
        section = text[text.index(heading) :].split("\n#", 1)[0]
        rows |= dict(re.findall(r"^\| `([a-z_]+)` \|([^\n]*)", section, flags=re.M))
    checked = 0
    for key, unit in SETTING_UNITS.items():
        if key not in rows:
            continue
        cells = rows[key].replace("m/s²", "")  # gravity's, on no number row
        checked += 1
        if unit:
            assert re.search(rf"(?<![\w/]){re.escape(unit)}(?![\w/²³])", cells), (key, unit, rows[key])
        else:
            for other in ("kg/m³", "m/s", "Hz", "rad"):
                assert other not in cells, (key, other, rows[key])
    assert (
        checked == 10
    )  # duration dt theta tolerance max_iterations record_every alert_distance density thickness friction


def test_scenario_format_counts_bodies_as_the_messages_do():
    # The page said geometry messages "count bodies from 0, as the model does" after they were numbered
    # from 1 (1b09016), next to its own example "blocks 4 ("b4") and 5 ("b5") overlap".
    text = (ROOT / "docs" / "scenario-format.md").read_text()
    assert "from 0" not in text
