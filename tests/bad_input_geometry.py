"""Bad-input catalogue rows about geometry files: GeoJSON and WKT, which run and check read alike. Each row is
(id, files, argv, exit code, fragment of the one line); tests/test_bad_input_catalogue.py runs them.
"""

from __future__ import annotations

import math

from bad_input_files import BLOCK, scen


def feature(coords, role: str = "block", name: str = "a", gtype: str = "Polygon") -> str:
    import json

    geometry = {"type": gtype, "coordinates": coords}
    return json.dumps(
        {
            "type": "FeatureCollection",
            "features": [{"type": "Feature", "properties": {"role": role, "name": name}, "geometry": geometry}],
        }
    )


SQUARE = [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]
CIRCLE = [
    [round(math.cos(2 * math.pi * k / 10001), 9), round(2 + math.sin(2 * math.pi * k / 10001), 9)] for k in range(10001)
]

# (id, files, argv, exit code, fragment of the one line)
GEOMETRY_ROWS = [
    # -- GeoJSON (run and check read it alike)
    ("geojson-not-json", {"g.geojson": "{ not json"}, ("check", "g.geojson"), 2, "g.geojson: "),
    (
        "geojson-string-coordinate",
        {"g.geojson": feature([[[0, 0], [1, 0], [1, "x"], [0, 0]]])},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 1: block 1 ("a"): coordinates must be [x, y] number pairs',
    ),
    (
        "geojson-nan",
        {"g.geojson": feature([[[0, 0], [1, 0], [1, float("nan")], [0, 0]]])},
        ("run", "g.geojson", "--no-recording"),
        2,
        'g.geojson: feature 1: block 1 ("a"): vertex 2 has a NaN',
    ),
    ("geojson-role", {"g.geojson": feature(SQUARE, role="roof")}, ("check", "g.geojson"), 2, "g.geojson: feature 1"),
    ("geojson-point", {"g.geojson": feature([0, 0], gtype="Point")}, ("check", "g.geojson"), 2, "g.geojson: feature 1"),
    (
        "geojson-non-convex",
        {"g.geojson": feature([[[0, 0], [2, 0], [1, 0.5], [1, 2], [0, 0]]])},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 1: block 1 ("a"): polygon is not convex',
    ),
    (
        "geojson-no-features",
        {"g.geojson": '{"type": "FeatureCollection", "features": []}'},
        ("check", "g.geojson"),
        2,
        "g.geojson: ",
    ),
    ("geojson-missing", {}, ("run", "nope.geojson"), 2, "nope.geojson: no such scenario or geometry file"),
    # it said "g.geojson:1: not a UTF-8 text file (byte 0, 0xff: … such as Windows-1252)"
    (
        "geojson-utf16",
        {"g.geojson": feature(SQUARE).encode("utf-16")},
        ("check", "g.geojson"),
        2,
        "g.geojson: a UTF-16 text file (it starts with UTF-16's byte-order mark); save it as UTF-8",
    ),
    # a 100 000-vertex circle was cleaned one vertex at a time for minutes before a word: now at most 10 000
    (
        "toml-too-many-vertices",
        scen(block=f'name = "disc"\npolygon = {CIRCLE}\n'),
        ("check", "s.toml"),
        2,
        '[[block]] #1 ("disc"): 10001 vertices, more than 10000 (an outline traced at every pixel?',
    ),
    ("geojson-too-many-vertices", {"g.geojson": feature([CIRCLE])}, ("check", "g.geojson"), 2, "10001 vertices"),
    # a closed ring (as GeoJSON and WKT write every ring) counts its distinct vertices: 10 001 and its repeated
    # first one were said '10002 vertices', and 10 000 closed were refused as 10 001
    (
        "geojson-closed-ring-vertices",
        {"g.geojson": feature([CIRCLE + CIRCLE[:1]])},
        ("check", "g.geojson"),
        2,
        ": 10001 vertices, more than 10000",
    ),
    # integers too large for a float (TOML and JSON read any size): "OverflowError: int too large to convert
    # to float", a traceback; and a JSON true read as the coordinate 1.0 without a word
    (
        "geojson-huge-integer",
        {"g.geojson": feature([[[0, 0], [10**400, 0], [1, 1], [0, 0]]])},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 1: block 1 ("a"): vertex 1 has a NaN or infinite coordinate',
    ),
    (
        "geojson-bool-coordinate",
        {"g.geojson": feature([[[0, 0], [True, 0], [1, 1], [0, 0]]])},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 1: block 1 ("a"): coordinates must be [x, y] number pairs',
    ),
    (  # the block was named "{'a': 1}" (a list "['x']", true "True") without a word
        "geojson-name-object",
        {"g.geojson": feature(SQUARE, name={"a": 1})},
        ("check", "g.geojson"),
        2,
        "g.geojson: feature 1: name must be a string, got {'a': 1}",
    ),
    # a "|" joins a joint's two names: "a|b|ground" was a|b on ground, or a on b|ground (limit's hinges, the
    # summaries); a newline (or U+2028) in a name cut every message naming the block into two lines
    (
        "geojson-name-bar",
        {"g.geojson": feature(SQUARE, name="a|b")},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 1: name "a|b" must not contain "|" (it joins the names of a joint\'s two bodies',
    ),
    (
        "geojson-name-newline",
        {"g.geojson": feature(SQUARE, name="a\nb")},
        ("check", "g.geojson"),
        2,
        'g.geojson: feature 1: name "a\\nb" must not contain control characters or line breaks',
    ),
    (
        "toml-name-bar",
        scen(block='name = "a|b"\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n'),
        ("check", "s.toml"),
        2,
        's.toml:2: [[block]] #1 ("a|b"): name = "a|b": must not contain "|"',
    ),
    (
        "toml-support-name-line-separator",
        {
            "s.toml": f'[[block]]\n{BLOCK}[[support]]\nname = "g\\u2028"\npolygon = [[-2, -1], [3, -1], [3, 0], [-2, 0]]\n'
        },
        ("check", "s.toml"),
        2,
        'name = "g\\u2028": must not contain control characters or line breaks',
    ),
    (
        "wkt-name-bar",
        {"w.wkt": "block a|b: POLYGON((0 0,1 0,1 1,0 1,0 0))\nsupport g: POLYGON((-2 -1,3 -1,3 0,-2 0,-2 -1))\n"},
        ("check", "w.wkt"),
        2,
        'w.wkt: block 1: name "a|b" must not contain "|"',
    ),
    # -- WKT
    (
        "wkt-nan",
        {"n.wkt": "POLYGON ((0 0, nan 0, 1 1, 0 1, 0 0))\n"},
        ("run", "n.wkt", "--no-recording"),
        2,
        'n.wkt: line 1: block 1 ("block-1"): vertex 1 has a NaN or infinite coordinate',
    ),
    ("wkt-garbage", {"n.wkt": "POLYGON ((0 0, 1 0\n"}, ("check", "n.wkt"), 2, "n.wkt: line 1"),
    # a LINESTRING is a ground line (the support under it); one of two parts is no line
    (
        "wkt-linestring",
        {"n.wkt": "MULTILINESTRING ((0 0, 1 0), (2 0, 3 0))\n"},
        ("check", "n.wkt"),
        2,
        "n.wkt: line 1: a MULTI",
    ),
]
