"""A record's text read chunk by chunk with numpy gives bit for bit what the per-line reading gives
(the reference), the same errors at the same lines, and an error deep in a big file is found fast."""

from __future__ import annotations

import pickle
import random

import numpy as np
import pytest

import masonrycli.records.text as rt
from masonrycli.errors import InputError
from masonrycli.records.read import load_at2, load_record_csv

from synthetic_records import write_at2

# every layout the per-line reading takes: (the lines before the samples, sample lines used in turn);
# the first ones are those numpy reads
LAYOUTS = {
    "comma": ("time,velocity\n", ["{t},{v}\n"]),
    "comma and spaces": ("# from a logger\ntime, vx, vy\n", ["{t}, {v}, {w}\n"]),
    "spaces": ("", ["{t} {v}\n"]),
    "tabs": ("t\tv\n", ["{t}\t{v}\t{w}\n"]),
    "semicolon, decimal commas": ("time;velocity\n", ["{tc};{vc}\n"]),
    "semicolon, points": ("\ufefftime;vx;vy\n", ["{t};{v};{w}\n"]),
    "tab, decimal commas": ("time\tvelocity\n", ["{tc}\t{vc}\n"]),
    "windows line ends": ("time,velocity\r\n", ["{t},{v}\r\n"]),
    # read line by line (numpy would differ from it): exact all the same
    "comma aligned with tabs": ("time,\tvel\n", ["{t},\t{v}\n"]),
    "trailing comma": ("", ["{t},{v},\n"]),
    "blank lines and comments": ("t,v\n", ["{t},{v}\n", "\n", "{t},{v}\n", "# note\n"]),
    "old mac line ends": ("t v\r", ["{t} {v}\r"]),
    "form feeds": ("t v\x0c", ["{t} {v}\x0c\n"]),
    "underscores": ("", ["{t}_0,{v}\n"]),
    "mixed separators": ("", ["{t},{v}\n", "{t} {v}\n", "{tc};{vc}\n", "{t}\t{vc}\n"]),
}


def layout_text(layout: str, n: int = 60, seed: int = 0) -> str:
    """A record of ``n`` random samples (numbers written in several ways) in ``layout``."""
    head, lines = LAYOUTS[layout]
    rng = random.Random(seed)
    t = np.cumsum([rng.uniform(1e-3, 1.0) for _ in range(n)])
    styles = [repr, lambda x: f"{x:.17g}", lambda x: f"{x:.3e}", lambda x: f"{x:.6f}", lambda x: str(int(x * 1000))]
    out = [head]
    for i in range(n):
        v, w = rng.uniform(-5, 5) * 10 ** rng.randint(-12, 3), rng.choice([0.0, -0.0, rng.gauss(0, 1)])
        style = rng.choice(styles)
        tt, vv, ww = repr(float(t[i])), style(v), style(w)
        fields = dict(t=tt, v=vv, w=ww, tc=tt.replace(".", ","), vc=vv.replace(".", ","))
        out.append(lines[i % len(lines)].format(**fields))
    return "".join(out)


def same(a, b) -> bool:
    return all(x.dtype == y.dtype and x.shape == y.shape and x.tobytes() == y.tobytes() for x, y in zip(a, b))


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("chunk", [1, 37, 400, rt.CHUNK_CHARS])
def test_every_layout_reads_bit_for_bit_as_line_by_line(monkeypatch, layout, chunk):
    # chunks of 1 and 37 characters cut the text after every line or every few: each piece is read
    # alone, by numpy or line by line
    monkeypatch.setattr(rt, "CHUNK_CHARS", chunk)
    for seed in range(3):
        text = layout_text(layout, seed=seed)
        ref = rt.csv_reference(text, "r.csv")
        got = rt.csv_text(text, "r.csv")
        assert same(got, ref), layout


def test_the_clean_layouts_are_read_by_numpy():
    # else the test above would compare the per-line reading with itself
    for layout, ncol in [("comma", 2), ("comma and spaces", 3), ("spaces", 2), ("tabs", 3), ("semicolon, points", 3)]:
        body = layout_text(layout)[len(LAYOUTS[layout][0]) :]
        assert rt._fast_csv_rows(body, ncol) is not None, layout
    for layout in ("semicolon, decimal commas", "tab, decimal commas"):
        body = layout_text(layout)[len(LAYOUTS[layout][0]) :]
        assert rt._fast_csv_rows(body, 2) is not None, layout
    assert rt._fast_csv_rows("1,2\n\n3,4", 2) is None  # a blank line would shift the line numbers
    assert rt._fast_csv_rows("0,\t5\n1,\t6", 2) is None  # the aligned CSV: per-line rules


def test_a_file_reads_as_its_text_line_by_line(tmp_path):
    for layout in LAYOUTS:
        text = layout_text(layout, n=200)
        f = tmp_path / "r.csv"
        f.write_bytes(text.encode())
        assert same(load_record_csv(f, display="r.csv"), rt.csv_reference(text.lstrip("\ufeff"), "r.csv")), layout


ERRORS = [
    "0,1\n0.1,abc\n",
    "t,v\n0,1\n1,2\n2,x\n3,4\n",
    "# c\n0,1,2,3\n",
    "0,1\n1,2,3\n",
    "0,1\n0.5,2\n0.5,3\n",
    "0,1\n1,nan\n",
    "0,1\n1,2\n2,inf\n3,1\n",
    "0;0,5\n1;1,234.5\n",
    "0\t0,5\n1\t0,5,5\n",
    "time,value\n0,1\n",
    "",
    "t,v\nx,y\n0,1\n",
    "0,1\n1,2\n3\n",
    "0 1\n1 2\n0.5 3\n",
]


@pytest.mark.parametrize("text", ERRORS)
@pytest.mark.parametrize("chunk", [1, 5, rt.CHUNK_CHARS])
def test_errors_are_those_of_the_line_by_line_reading(monkeypatch, text, chunk):
    monkeypatch.setattr(rt, "CHUNK_CHARS", chunk)
    with pytest.raises(InputError) as ref:
        rt.csv_reference(text, "bad.csv")
    with pytest.raises(InputError) as got:
        rt.csv_text(text, "bad.csv")
    assert str(got.value) == str(ref.value)


def big_record(n: int) -> str:
    # "time,velocity" then n rows "i,0.5": row i (from 0) on line i + 2
    return "time,velocity\n" + ",0.5\n".join(map(str, range(n))) + ",0.5\n"


@pytest.fixture(scope="module")
def three_million_rows() -> str:
    return big_record(3_000_000)


@pytest.mark.parametrize(
    "bad, message",
    [
        ("1999999,abc", 'big.csv:2000001: not a number: "abc"'),
        ("1999997,0.5", "big.csv:2000001: time 1999997.0 is not after the previous sample's 1999998.0"),
        ("1999999,nan", 'big.csv:2000001: values must be finite, got "1999999,nan"'),
    ],
)
def test_an_error_deep_in_a_big_file_names_its_line_and_reads_few_lines_one_by_one(
    tmp_path, monkeypatch, three_million_rows, bad, message
):
    # 3 million rows (a 4 h record at 200 Hz); the row on line 2 000 001 is bad
    text = three_million_rows.replace("\n1999999,0.5\n", f"\n{bad}\n")
    f = tmp_path / "big.csv"
    f.write_text(text)
    read = []
    careful = rt.csv_lines

    def counting(lines, *args):
        read.append(len(lines))
        return careful(lines, *args)

    monkeypatch.setattr(rt, "csv_lines", counting)
    with pytest.raises(InputError) as exc:
        load_record_csv(f, display="big.csv")
    assert str(exc.value).startswith(message)
    assert sum(read) < 200_000  # the header, and the chunk holding the bad line


def test_a_big_file_is_read_by_numpy(tmp_path, monkeypatch):
    f = tmp_path / "big.csv"
    f.write_text(big_record(1_000_000))
    read = []
    careful = rt.csv_lines
    monkeypatch.setattr(rt, "csv_lines", lambda lines, *args: read.append(lines) or careful(lines, *args))
    t, v = load_record_csv(f)
    assert t.size == 1_000_000 and t[-1] == 999_999.0 and np.all(v == 0.5)
    assert read == [["time,velocity"], ["0,0.5"]]  # the header, and the first sample: its column count


# -------------------------------------------------------------------------------------------- one column

# one value per line (a time step given): the layouts a one-column file may come in
ONE_COLUMN = {
    "plain": ("", ["{v}\n"]),
    "header": ("acceleration\n", ["{v}\n"]),
    "comment, spaces": ("# station 12\nvalue\n", ["  {v}  \n"]),
    "windows line ends": ("v\r\n", ["{v}\r\n"]),
    "blank lines": ("", ["{v}\n", "\n"]),
    "form feeds": ("v\x0c", ["{v}\x0c\n"]),
}


def one_column_text(layout: str, n: int = 60, seed: int = 0) -> str:
    head, lines = ONE_COLUMN[layout]
    rng = random.Random(seed)
    styles = [repr, lambda x: f"{x:.17g}", lambda x: f"{x:.3e}", lambda x: f"{x:.6f}"]
    values = [rng.choice(styles)(rng.uniform(-5, 5) * 10 ** rng.randint(-12, 3)) for _ in range(n)]
    return head + "".join(lines[i % len(lines)].format(v=v) for i, v in enumerate(values))


@pytest.mark.parametrize("layout", ONE_COLUMN)
@pytest.mark.parametrize("chunk", [1, 37, rt.CHUNK_CHARS])
def test_one_column_reads_bit_for_bit_as_line_by_line(monkeypatch, layout, chunk):
    monkeypatch.setattr(rt, "CHUNK_CHARS", chunk)
    for seed in range(3):
        text = one_column_text(layout, seed=seed)
        ref = rt.csv_reference(text, "a.csv", time_step=0.01)
        got = rt.csv_text(text, "a.csv", time_step=0.01)
        assert same(got, ref) and got[1].ndim == 1, layout
        # the values are the lines' numbers, in order; the times 0, dt, 2 dt, ... (as an .AT2 file's)
        lines = [line for line in text.splitlines() if not line.startswith("#")]
        numbers = [float(x) for line in lines for x in line.split() if x[0] in "-0123456789"]
        assert got[1].tolist() == numbers and got[0].tolist() == [i * 0.01 for i in range(len(numbers))]
    body = one_column_text("plain")
    assert rt._fast_csv_rows(body, 1) is not None  # else the test compared the per-line reading with itself


ONE_COLUMN_ERRORS = [
    ("0.1\n0.2\nabc\n", 'a.csv:3: not a number: "abc"'),
    ("v\n0.1\n0.2\n0.3,0.4\n", "a.csv:4: expected 1 column like the first sample, got 2"),
    ("0.1\nnan\n", 'a.csv:2: values must be finite, got "nan"'),
    ("v\n0.5\n", "a.csv: a record needs at least 2 samples, found 1"),
    ("t,v\n0,0.5\n0.01,0.6\n", "a.csv:2: 2 columns, but a time step was given: it is for a file of one value"),
    ("0 1 2\n", "a.csv:1: 3 columns, but a time step was given"),
]


@pytest.mark.parametrize("text, message", ONE_COLUMN_ERRORS)
@pytest.mark.parametrize("chunk", [1, 5, rt.CHUNK_CHARS])
def test_one_column_errors_are_those_of_the_line_by_line_reading(monkeypatch, text, message, chunk):
    monkeypatch.setattr(rt, "CHUNK_CHARS", chunk)
    with pytest.raises(InputError) as ref:
        rt.csv_reference(text, "a.csv", time_step=0.01)
    with pytest.raises(InputError) as got:
        rt.csv_text(text, "a.csv", time_step=0.01)
    assert str(got.value) == str(ref.value) and str(got.value).startswith(message)


@pytest.mark.parametrize("chunk", [1, rt.CHUNK_CHARS])
def test_one_column_without_a_time_step_says_to_give_one(monkeypatch, chunk):
    monkeypatch.setattr(rt, "CHUNK_CHARS", chunk)
    for text, line in [("0.1\n0.2\n", 1), ("acc\n\n0.1\n0.2\n", 3)]:
        with pytest.raises(InputError) as got:
            rt.csv_text(text, "a.csv")
        assert str(got.value) == (
            f"a.csv:{line}: one value per line, no times: give the time between samples: --record-dt SECONDS "
            "(a scenario's record table: time_step = SECONDS)"
        )
        # a command with one way to give it names that way; the refusal pickles as it was made
        assert isinstance(got.value, rt.NoTimeStep) and str(got.value.give("T")).endswith("samples: T")
        back = pickle.loads(pickle.dumps(got.value.give("T")))
        assert str(back) == str(got.value.give("T")) and back.where == f"a.csv:{line}"


def test_a_time_column_with_a_time_step_names_the_time_step_as_the_caller_gave_it():
    with pytest.raises(InputError) as got:
        rt.csv_text("t,v\n0,0.5\n0.01,0.6\n", "a.csv", time_step=0.01)
    # the Python keyword (a scenario's key too); the command line names its option, never both
    assert str(got.value).endswith("(this one has a time column: leave out time_step)")
    assert isinstance(got.value, rt.TimeStepNotUsed)
    named = got.value.named("--record-dt")
    assert str(named) == (
        "a.csv:2: 2 columns, but a time step was given: it is for a file of one value per line (this one has a "
        "time column: leave out --record-dt)"
    )
    back = pickle.loads(pickle.dumps(named))
    assert str(back) == str(named) and back.where == "a.csv:2"


# --------------------------------------------------------------------------------------------------- .AT2


def at2_text(values, per_line=5, breaks="\n") -> str:
    head = "PEER\nSTATION\nACCELERATION TIME SERIES IN UNITS OF G\nNPTS= {n}, DT= 0.0100 SEC\n"
    lines = [" ".join(values[i : i + per_line]) for i in range(0, len(values), per_line)]
    return head.format(n=len(values)) + breaks.join(lines) + "\n"


@pytest.mark.parametrize("chunk", [1, 23, rt.CHUNK_CHARS])
def test_at2_reads_bit_for_bit_as_line_by_line(tmp_path, monkeypatch, chunk):
    monkeypatch.setattr(rt, "CHUNK_CHARS", chunk)
    rng = random.Random(4)
    values = [rng.choice([repr, "{:15.7E}".format, "{:.3f}".format])(rng.uniform(-3, 3)) for _ in range(203)]
    for per_line, breaks in [(5, "\n"), (8, "\n"), (1, "\n"), (5, "\r\n"), (5, "\x0c\n"), (3, "\n\n")]:
        text = at2_text(values, per_line, breaks)
        f = tmp_path / "r.AT2"
        f.write_bytes(text.encode())
        dt, acc = load_at2(f)
        ref = rt.at2_reference(text.splitlines()[4:], "r.AT2", len(values))
        assert dt == 0.01 and same((acc,), (ref,))
    write_at2(tmp_path / "w.AT2", [float(v) for v in values], 0.01)
    text = (tmp_path / "w.AT2").read_text()
    assert same((load_at2(tmp_path / "w.AT2")[1],), (rt.at2_reference(text.splitlines()[4:], "w.AT2", 203),))


@pytest.mark.parametrize(
    "samples, message",
    [
        ("0.1 0.2\n0.3 x\n", 'bad.AT2:6: not a number: "x"'),
        ("0.1 0.2\n0.3 0.4\n\n0.5 nan\n", 'bad.AT2:8: values must be finite, got "nan"'),
        ("0.1 0.2\n0.3\x0c0.4\n-29.4\n", "bad.AT2:8: sample -29.4 g is beyond 10 g"),
    ],
)
@pytest.mark.parametrize("chunk", [1, 9, rt.CHUNK_CHARS])
def test_at2_errors_are_those_of_the_line_by_line_reading(tmp_path, monkeypatch, samples, message, chunk):
    monkeypatch.setattr(rt, "CHUNK_CHARS", chunk)
    f = tmp_path / "bad.AT2"
    f.write_text("a\nb\nc\nNPTS= 5, DT= 0.01 SEC\n" + samples)
    with pytest.raises(InputError) as ref:
        rt.at2_reference(f.read_text().splitlines()[4:], "bad.AT2", 5)
    with pytest.raises(InputError) as got:
        load_at2(f, display="bad.AT2")
    assert str(got.value) == str(ref.value) and str(got.value).startswith(message)


def test_at2_samples_after_npts_may_exceed_10_g(tmp_path):
    # only the first NPTS are checked against 10 g (the rest are ignored, with a warning)
    f = tmp_path / "long.AT2"
    f.write_text("a\nb\nc\nNPTS= 2, DT= 0.01 SEC\n0.1 0.2 50.0\n")
    with pytest.warns(UserWarning, match="the 1 after the first 2 are ignored"):
        assert load_at2(f)[1].tolist() == [0.1, 0.2]
