"""Record files: CSV formats, error messages naming file and line, the Record motion they make."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from masonrycli.errors import InputError
from masonrycli.records import load_record_csv, record_motion

DATA = Path(__file__).parent / "data"


def one_line(exc_info) -> str:
    msg = str(exc_info.value)
    assert "\n" not in msg and msg.strip() == msg and msg
    return msg


def test_load_record_csv_formats(tmp_path):
    t, v = load_record_csv(DATA / "quake_velocity.csv")
    np.testing.assert_array_equal(t, [0.0, 0.1, 0.2, 0.3, 0.4])
    np.testing.assert_array_equal(v, [0.0, 0.2, -0.1, 0.05, 0.0])
    f = tmp_path / "semi.csv"
    f.write_text("\ufefftime;vx;vy\n\n# comment\n0;1;2\n  1 ;  3 ; 4  \n2\t5\t6\n")
    t, v = load_record_csv(f)
    np.testing.assert_array_equal(t, [0, 1, 2])
    np.testing.assert_array_equal(v, [[1, 2], [3, 4], [5, 6]])


def test_record_motion_source_is_absolute():
    m = record_motion(DATA / "quake_velocity.csv", scale=2.0)
    assert Path(m.source).is_absolute() and Path(m.source).name == "quake_velocity.csv"
    assert m.describe().startswith("record of velocity (quake_velocity.csv, 5 samples")
    assert m.velocity_at([0.1])[0, 0] == pytest.approx(0.4)


@pytest.mark.parametrize(
    "text, expected",
    [
        ("0,1\n0.1,abc\n", 'bad.csv:2: not a number: "abc"'),
        ("# c\n0,1,2,3\n", "bad.csv:2: expected 2 columns (time, value) or 3 (time, x, y), got 4"),
        ("0,1\n1,2,3\n", "bad.csv:2: expected 2 columns like the first sample, got 3"),
        ("0,1\n0.5,2\n0.5,3\n", "bad.csv:3: time 0.5 is not after the previous sample's 0.5"),
        ("0,1\n1,nan\n", "bad.csv:2: values must be finite"),
        ("time,value\n0,1\n", "bad.csv: a record needs at least 2 samples, found 1"),
        ("", "bad.csv: a record needs at least 2 samples, found 0"),
        ("t,v\nx,y\n0,1\n", 'bad.csv:2: not a number: "x"'),
    ],
)
def test_load_record_csv_errors_name_file_and_line(tmp_path, text, expected):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(InputError) as exc:
        load_record_csv(f, display="bad.csv")
    assert expected in one_line(exc)


def test_load_record_csv_unreadable(tmp_path):
    with pytest.raises(InputError) as exc:
        load_record_csv(tmp_path / "missing.csv")
    assert "missing.csv: cannot read record" in one_line(exc)
    with pytest.raises(InputError) as exc:
        load_record_csv(tmp_path)
    assert "is a directory" in one_line(exc)
    f = tmp_path / "latin1.csv"
    f.write_bytes(b"0,1\n1,\xe9\n")
    with pytest.raises(InputError) as exc:
        load_record_csv(f)
    assert "latin1.csv: not a UTF-8 text file" in one_line(exc)
