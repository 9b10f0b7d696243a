"""Property-based bad input: random TOML documents, GeoJSON features and polygons (convex, non-convex,
degenerate, huge, NaN) fed to the readers and the geometry checks. Whatever the input, the answer is a
scenario (exit 0) or one line and exit 2 — never a traceback or another exception."""

from __future__ import annotations

import json
import math
import re

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from geometry_library.blocks import GeometryError
from geometry_library.checks import polygon_from_coords
from masonrycli.cli.app import app
from masonrycli.errors import InputError
from masonrycli.scenario.toml_file import loads_scenario
from masonrycli.scenario.toml_lines import message_key
from masonrycli.scenario.values import format_value, quote_key

SETTINGS = settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

coordinate = st.one_of(
    st.floats(-10, 10, allow_nan=False),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, 1.0, 1e300, -1e300, math.nan, math.inf, 1e-300]),
)
point = st.lists(coordinate, min_size=2, max_size=2)
box = st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(0, 3), st.floats(0, 3)).map(
    lambda b: [[b[0], b[1]], [b[0] + b[2], b[1]], [b[0] + b[2], b[1] + b[3]], [b[0], b[1] + b[3]]]
)
polygon = st.one_of(box, st.lists(point, min_size=0, max_size=8))  # convex boxes (some degenerate) or anything

scalar = st.one_of(
    st.integers(-(10**6), 10**20),
    st.floats(allow_nan=True, allow_infinity=True),
    st.booleans(),
    st.text(max_size=8),
)
value = st.recursive(scalar, lambda inner: st.lists(inner, max_size=4), max_leaves=8)
run_table = st.dictionaries(
    st.sampled_from(["duration", "dt", "theta", "record_every", "tolerance", "max_iterations", "gravity", "x"]),
    value,
    max_size=4,
)
motion = st.one_of(
    st.none(),
    st.dictionaries(
        st.sampled_from(["kind", "amplitude", "frequency", "velocity", "direction", "time", "value", "file"]),
        st.one_of(value, st.sampled_from(["sine", "fixed", "constant", "ramp", "record", "wobble"])),
        max_size=4,
    ),
)
block = st.fixed_dictionaries(
    {"polygon": polygon}, optional={"name": st.text(max_size=6), "density": value, "velocity": value}
)
support = st.fixed_dictionaries({"polygon": polygon}, optional={"name": st.text(max_size=6), "motion": motion})


def toml_table(table: dict) -> str:
    return "".join(f"{quote_key(k)} = {format_value(v)}\n" for k, v in table.items() if v is not None)


@st.composite
def scenario_text(draw) -> str:
    parts = []
    if draw(st.booleans()):
        parts.append("[run]\n" + toml_table(draw(run_table)))
    for b in draw(st.lists(block, max_size=3)):
        parts.append("[[block]]\n" + toml_table(b))
    for s in draw(st.lists(support, max_size=2)):
        parts.append("[[support]]\n" + toml_table(s))
    if draw(st.booleans()):  # raw garbage sometimes
        parts.append(draw(st.text(max_size=20)))
    return "\n".join(parts)


@SETTINGS
@given(scenario_text())
def test_random_toml_is_a_scenario_or_one_line(text):
    try:
        loads_scenario(text, source="r.toml")
    except InputError as exc:
        message = str(exc)
        where = re.match(r"r\.toml(?::([1-9][0-9]*))?: ", message)
        assert len(message.splitlines()) == 1 and where, message
        if where.group(1):  # a key's line (masonrycli/scenario/toml_lines.py): the key the message names is on it
            path, key = message_key(message[where.end() :])
            assert key in text.split("\n")[int(where.group(1)) - 1], (message, text)


@SETTINGS
@given(polygon, st.sampled_from(["block", "support"]))
def test_random_polygon_is_convex_or_one_line(coords, kind):
    try:
        poly = polygon_from_coords(coords, 0, "p", kind)
    except GeometryError as exc:
        assert len(str(exc).splitlines()) == 1 and str(exc).startswith(f'{kind} 1 ("p")')  # index 0, shown from 1
    else:
        assert poly.is_valid and poly.area > 0 and math.isclose(poly.convex_hull.area, poly.area, rel_tol=1e-9)


def feature(draw_polygon, role, name, gtype) -> dict:
    ring = draw_polygon + draw_polygon[:1]
    coordinates = [ring] if gtype == "Polygon" else ring
    return {
        "type": "Feature",
        "properties": {"role": role, "name": name},
        "geometry": {"type": gtype, "coordinates": coordinates},
    }


features = st.lists(
    st.builds(
        feature,
        polygon,
        st.sampled_from(["block", "support", "roof", None]),
        st.text(max_size=5),
        st.sampled_from(["Polygon", "LineString", "Point"]),
    ),
    max_size=3,
)


def assert_exit_0_or_one_line_2(result):
    assert "Traceback" not in result.output
    assert result.exit_code in (0, 2), result.output
    if result.exit_code == 2:
        lines = [ln for ln in result.output.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: "), result.output


@SETTINGS
@given(features)
def test_random_geojson_checks_with_exit_0_or_one_line(tmp_path, feats):
    path = tmp_path / "g.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": feats}))
    assert_exit_0_or_one_line_2(CliRunner().invoke(app, ["check", str(path)]))


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(scenario_text())
def test_random_toml_checks_with_exit_0_or_one_line(tmp_path, text):
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    assert_exit_0_or_one_line_2(CliRunner().invoke(app, ["check", str(path)]))
