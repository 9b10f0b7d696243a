"""The one definition of a valid number: reasons, bounds, bools, and the two message styles built on it."""

import math

import numpy as np
import pytest

from geometry_library.blocks import GeometryError
from geometry_library.values import (
    SETTING_UNITS,
    TypedNumber,
    check_count,
    check_positive,
    is_integer,
    is_real,
    number_problem,
    same_unit,
)
from masonrycli.errors import InputError
from masonrycli.scenario.values import check_int, check_real


@pytest.mark.parametrize(
    "value, kwargs, reason",
    [
        (1.5, {}, None),
        (np.float32(2.0), {"gt": 0.0}, None),
        (True, {}, "must be a number"),
        ("2", {}, "must be a number, not a string (write 2, without quotes)"),  # was "must be a number"
        (" 1e-3", {"gt": 0.0}, "must be a number, not a string (write 1e-3, without quotes)"),
        ("abc", {}, "must be a number, not a string"),
        ("10", {"integer": True}, "must be an integer, not a string (write 10, without quotes)"),
        (None, {}, "must be a number"),
        (math.nan, {}, "must be a finite number"),
        (math.inf, {}, "must be a finite number"),
        (math.inf, {"allow_inf": True, "le": 1.0}, "must be <= 1"),
        (-math.inf, {"allow_inf": True}, "must be a finite number"),
        (0.0, {"gt": 0.0}, "must be > 0"),
        (0.4, {"ge": 0.5}, "must be >= 0.5"),
        (1.0, {"lt": 1.0}, "must be < 1"),
        (2e5, {"le": 1e5}, "must be <= 100000"),
        (3, {"integer": True, "ge": 1}, None),
        (np.int64(0), {"integer": True, "ge": 1}, "must be >= 1"),
        (2.0, {"integer": True}, "must be an integer"),
        (np.bool_(True), {"integer": True}, "must be an integer"),
        (10**9 + 1, {"integer": True, "le": 10**9}, "must be <= 1000000000"),  # an integer bound as written
    ],
)
def test_number_problem(value, kwargs, reason):
    assert number_problem(value, **kwargs) == reason


@pytest.mark.parametrize(
    "value, unit, reason",
    [
        # "1 s" said "must be a number, not a string": which number, in which unit, was left to guess
        ("1 s", "s", "must be a number, not a string (write 1, in s, without the unit)"),
        ("0.5m", "m", "must be a number, not a string (write 0.5, in m, without the unit)"),
        ("2 Hz", "Hz", "must be a number, not a string (write 2, in Hz, without the unit)"),
        ("2500 kg/m3", "kg/m³", "must be a number, not a string (write 2500, in kg/m³, without the unit)"),
        ("2500 kg/m^3", "kg/m³", "must be a number, not a string (write 2500, in kg/m³, without the unit)"),
        ("2500 kg/m³", "kg/m³", "must be a number, not a string (write 2500, in kg/m³, without the unit)"),
        (" 1e-3 Seconds ", "s", "must be a number, not a string (write 1e-3, in s, without the unit)"),
        ("1 m/s", "m/s", "must be a number, not a string (write 1, in m/s, without the unit)"),
        # another unit than the setting's: said, never converted here
        (
            "20 ms",
            "s",
            "must be a number, not a string (it is read in s: convert 20 ms to s and write the number alone)",
        ),
        (
            "2.5 t/m3",
            "kg/m³",
            "must be a number, not a string (it is read in kg/m³: convert 2.5 t/m3 to kg/m³ and write the number alone)",
        ),
        (
            "90°",
            "rad",
            "must be a number, not a string (it is read in rad: convert 90° to rad and write the number alone)",
        ),
        (
            "1 m/s",
            "m",
            "must be a number, not a string (it is read in m: convert 1 m/s to m and write the number alone)",
        ),
        ("0.6 mu", "", 'must be a number, not a string (write 0.6, without "mu": this setting has no unit)'),
        ("0.5 m/s", None, 'must be a number, not a string (write 0.5, without "m/s", in SI units)'),
        ("1,5 m", "m", "must be a number, not a string"),  # a decimal comma: no number to name
        ("one s", "s", "must be a number, not a string"),
        # not a number and a unit: said "convert 0 x10 to m" (a hex literal read as 0 and "x10")
        ("0x10", "m", "must be a number, not a string"),
        ("0xff", "m", "must be a number, not a string"),
        ("1e", "m", "must be a number, not a string"),
        ("2x3", "m", "must be a number, not a string"),
        ("3 m;4", "m", "must be a number, not a string"),
        # a hint only when a unit follows the number ("12abc" said "convert 12 abc to m")
        ("12abc", "m", "must be a number, not a string"),
        ("12 abc", "", "must be a number, not a string"),
        ("12 abc", None, "must be a number, not a string"),
        ("5x", "m", "must be a number, not a string"),
        ("5x", "", 'must be a number, not a string (write 5, without "x": this setting has no unit)'),
        ("3 kN", "m", "must be a number, not a string (it is read in m: convert 3 kN to m and write the number alone)"),
        (
            "12mm",
            "m",
            "must be a number, not a string (it is read in m: convert 12 mm to m and write the number alone)",
        ),
        (
            "2 Millimetres",
            "m",
            "must be a number, not a string (it is read in m: convert 2 Millimetres to m and write the number alone)",
        ),
        ("2500", "kg/m³", "must be a number, not a string (write 2500, without quotes)"),
    ],
)
def test_a_number_written_with_its_unit_is_told_what_to_write(value, unit, reason):
    assert number_problem(value, gt=0.0, unit=unit) == reason


def test_an_integer_written_with_a_unit():
    assert number_problem("51 blocks", integer=True, unit="") == (
        'must be an integer, not a string (write 51, without "blocks": this setting has no unit)'
    )


def test_every_setting_unit_has_its_spellings():
    assert set(SETTING_UNITS.values()) - {""} <= {"s", "m", "kg/m³", "m/s", "Hz", "rad"}
    for unit in set(SETTING_UNITS.values()) - {""}:
        assert same_unit(unit, unit) and not same_unit("furlong", unit)
    assert same_unit("KG/M**3", "kg/m³") and same_unit("m s-1", "m/s") and not same_unit("ms", "s")


def test_is_real_and_is_integer_reject_bools():
    assert is_real(3) and is_real(np.float64(0.1)) and not is_real(False) and not is_real(np.bool_(False))
    assert is_integer(np.int32(4)) and not is_integer(4.0) and not is_integer(True)


def test_geometry_style_messages():
    check_positive("wall", a=0.1, b=np.float64(2.0))
    with pytest.raises(GeometryError, match=r"^wall: b must be a positive number, got -1\.0$"):
        check_positive("wall", a=0.1, b=-1.0)
    with pytest.raises(GeometryError, match=r"^block 3: density must be a positive number, got True$"):
        check_positive("block 3", density=True)
    # a GeoJSON's "density": "2500" said "density must be a positive number, got '2500'"
    with pytest.raises(GeometryError, match=r"^b 1: density must be a number, not a string \(write 2500, without"):
        check_positive("b 1", density="2500")
    # a GeoJSON's "density": "2500 kg/m3" (the unit of the property named too)
    with pytest.raises(GeometryError, match=r"^b 1: density must be a number, not a string \(write 2500, in kg/m³, "):
        check_positive("b 1", density="2500 kg/m3")
    check_count("arch", 2, voussoirs=np.int64(2))
    with pytest.raises(GeometryError, match=r"^arch: voussoirs must be an integer ≥ 2, got 1$"):
        check_count("arch", 2, voussoirs=1)


def test_input_style_messages():
    assert check_real("dt", 1) == 1.0 and isinstance(check_real("dt", 1), float)
    with pytest.raises(InputError, match=r"^dt = -0\.001: must be > 0$"):
        check_real("dt", -0.001, gt=0.0)
    assert check_int("n", np.int64(5), ge=1, le=10) == 5
    with pytest.raises(InputError, match=r"^record_every = 0: must be >= 1$"):
        check_int("record_every", 0, ge=1, le=10**9)
    with pytest.raises(InputError, match=r"^record_every = 2\.5: must be an integer$"):
        check_int("record_every", 2.5, ge=1, le=10**9)


def test_material_outside_its_range_is_absurd():
    # thickness 1e300 divided by zero in the engine ("internal error"), density 1e-300 reported a resting
    # wall collapsed at its first step; the dynamics is the same over the whole range
    from geometry_library.values import check_material

    check_material("block 0", density=1e-3, thickness=1e3)
    check_material("block 0", density=1e5, thickness=1e-6)
    with pytest.raises(
        GeometryError, match=r"^block 0: thickness 1e\+300 m is absurd \(a likely typo: 1e-06 to 1000 m\)$"
    ):
        check_material("block 0", thickness=1e300)
    with pytest.raises(GeometryError, match=r"^block 0: density 1e-300 kg/m³ is absurd"):
        check_material("block 0", density=1e-300)
    with pytest.raises(GeometryError, match="must be a positive number"):
        check_material("block 0", density=-1.0)
    # a value typed on the command line is echoed as typed (said "thickness 1e+09 m")
    with pytest.raises(GeometryError, match=r"^block 0: thickness 1e9 m is absurd"):
        check_material("block 0", thickness=TypedNumber(1e9, "1e9"))


def test_a_typed_number_writes_and_hashes_as_the_float_it_is():
    # An option's value keeps its text for messages only (cli.option_values.number_value): every value written
    # or digested from a scenario must be the plain float's, and a Dask worker's copy keeps the text.
    import json
    import pickle

    from masonrycli.scenario.values import format_value

    for text in ("0.1", "1e9", "2e-3", "-0", "3"):
        typed, plain = TypedNumber(float(text), text), float(text)
        assert (repr(typed), str(typed), hash(typed), format_value(typed)) == (
            repr(plain),
            str(plain),
            hash(plain),
            format_value(plain),
        )
        assert json.dumps([typed]) == json.dumps([plain])
        assert np.array([typed]).dtype == np.float64 and np.array([typed]).tobytes() == np.array([plain]).tobytes()
        assert type(typed + 0.0) is float and type(float(typed)) is float
        back = pickle.loads(pickle.dumps(typed))
        assert type(back) is TypedNumber and back.text == text and repr(back) == repr(plain)
