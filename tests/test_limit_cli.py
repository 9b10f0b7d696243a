"""``masonry limit`` as a user drives it: table, one JSON object, recording, bad input in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from masonrycli import SOURCE_DIGEST
from masonrycli.cli.app import app
from masonrycli.scenario.toml_file import dump_scenario

from cli_helpers import assert_one_line_error, invoke, runner, signal_inside_a_ctypes_callback, words
from limit_helpers import column, semicircular_arch


@pytest.fixture(scope="module")
def column_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("limit") / "column.toml"
    path.write_text(dump_scenario(column(3, 0.4, 0.2, 0.9)))
    return path


def test_json_is_one_object_with_the_load_factor_hinges_and_sliding_joints(column_file):
    result = runner.invoke(app, ["limit", str(column_file), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)  # the whole of stdout is one JSON object
    assert data["load_factor"] == pytest.approx(0.4 / (3 * 0.2), rel=5e-3)
    assert data["hinges"] == ["b0|ground"] and data["sliding_joints"] == []
    assert data["solve_time_s"] > 0 and data["tilt_angle_deg"] > 0
    assert {"line_of_thrust", "mechanism", "collapse_load_N", "hinge_points"} <= set(data)
    assert data["source_digest"] == SOURCE_DIGEST and data["commit"] and data["masonry"]  # what answered


def test_table_names_lambda_and_mechanism(column_file, tmp_path):
    out = tmp_path / "col.rrd"
    result = invoke("limit", column_file, "--load", "tilt", "--direction", "-x", "--out", out)
    assert result.exit_code == 0, result.output
    assert "0.6667" in result.output and "b0|ground" in result.output
    assert "3 blocks, 1 support, friction μ = 0.9" in result.output  # was "1 supports"
    assert out.stat().st_size > 0


def test_a_mechanism_that_slides_is_said_to_overstate_lambda_maybe(column_file, tmp_path):
    """The LP's slide dilates (associative flow), the engine's does not: a column of 3 blocks 0.4 × 0.2 m on μ =
    0.2 slides at λ = μ (it would rock at B/H = 0.667) and the table says λ may overstate; rocking at μ = 0.9
    it does not say so."""
    sliding = tmp_path / "sliding.toml"
    sliding.write_text(dump_scenario(column(3, 0.4, 0.2, 0.2)))
    said = invoke("limit", sliding).output
    assert "0.2000" in said and "λ, as it slides" in said and "may overstate" in said
    assert "as it slides" not in invoke("limit", column_file).output


def test_no_friction_gives_zero_not_minus_zero(column_file):
    # A frictionless column slides at once: λ = 0, which HiGHS returns as -0.0 ("λ = -0.0000 (tilt ψ =
    # -0.00°)", "collapse load -0 N", "load_factor": -0.0 in the JSON)
    table = invoke("limit", column_file, "--friction", "0")
    assert table.exit_code == 0 and "0.0000  (a horizontal acceleration of 0 g" in table.output
    assert "tilt ψ = 0.00°)" in table.output and "-0" not in table.output
    data = json.loads(invoke("limit", column_file, "--friction", "0", "--json").stdout)
    assert str(data["load_factor"]) == "0.0" and str(data["collapse_load_N"]) == "0.0"


def test_verify_at_zero_lambda_says_there_is_nothing_to_verify(column_file):
    # λ = 0 (frictionless): --verify ran the unloaded column twice, "0.95" and "1.05" × 0, and printed a red
    # "no" under "predicted" for the second (it stands: no load at all), exit 0, no word why.
    result = invoke("limit", column_file, "--friction", "0", "--verify")
    said = words(result.output)
    assert result.exit_code == 0, result.output
    assert "--verify: λ = 0, so 0.95 λ and 1.05 λ are both the unloaded structure: nothing to verify" in said, said
    assert "predicted" not in said
    data = json.loads(runner.invoke(app, ["limit", str(column_file), "--friction", "0", "--verify", "--json"]).stdout)
    assert data["verify"] == []


def test_point_load_on_a_named_block(column_file):
    result = runner.invoke(
        app, ["limit", str(column_file), "--load", "point", "--block", "b2", "--direction", "+x", "--json"]
    )
    data = json.loads(result.stdout)
    # Top block of 3: overturning of the whole column 3B/(5H) = 1.2 > μ = 0.9, so the top block slides.
    assert data["load_factor"] == pytest.approx(0.9, rel=5e-3)
    assert data["sliding_joints"] == ["b1|b2"] and data["load"]["block"] == "b2"


def test_verify_with_json_is_still_one_object(tmp_path):
    path = tmp_path / "block.toml"
    path.write_text(dump_scenario(column(1, 0.4, 0.8, 0.9)))
    result = runner.invoke(app, ["limit", str(path), "--load", "tilt", "--verify", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert [c["factor"] for c in data["verify"]] == [0.95, 1.05]
    assert [c["collapsed"] for c in data["verify"]] == [False, True]
    assert all(c["as_predicted"] for c in data["verify"])


def test_built_in_arch_by_name():
    result = runner.invoke(app, ["limit", "arch", "--json"])
    data = json.loads(result.stdout)
    assert data["blocks"] == 98 and 0 < data["load_factor"] < 1 and data["hinges"]


@pytest.mark.parametrize(
    ("args", "fragments"),
    [
        (["nowhere.toml"], ["nowhere.toml", "no such scenario"]),
        (["arch", "--load", "wind"], ["--load wind"]),
        (["arch", "--load", "point"], ["--block NAME"]),
        (["arch", "--load", "point", "--block", "v99"], ["--block v99", "no such block"]),
        # a support named as the loaded block: "no such block (1 blocks, e.g. ...)" for a one-block file
        (["arch", "--load", "point", "--block", "left-foundation"], ["--block left-foundation: a support, not a"]),
        (["arch", "--direction", "up"], ["--direction up"]),
        (["arch", "--friction", "-1"], ["--friction"]),
        # the LP called the wall unable to carry its own weight at μ = 1e8 ("no equilibrium ..."): refused
        (["wall", "--friction", "1e8"], ["--friction: friction = 1e8: must be <= 1000"]),
        (["arch", "--out", "x.png"], ["--out x.png", ".rrd"]),
    ],
)
def test_bad_input_is_one_line(args, fragments):
    assert_one_line_error(invoke("limit", *args), *fragments)


def test_an_unknown_block_of_a_one_block_file_is_counted_in_the_singular(tmp_path):
    path = tmp_path / "one.toml"
    path.write_text(dump_scenario(column(1, 0.4, 0.8, 0.9)))
    assert_one_line_error(invoke("limit", path, "--load", "point", "--block", "zzz"), "no such block (1 block, e.g.")


def test_infeasible_structure_is_one_line_exit_2(tmp_path):
    path = tmp_path / "thin.toml"
    path.write_text(
        '[material]\nfriction = 2.0\n[[block]]\nname = "leaning"\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n'
        '[[support]]\nname = "ground"\npolygon = [[-1, -1], [0.3, -1], [0.3, 0], [-1, 0]]\n'
    )
    assert_one_line_error(invoke("limit", path), "no equilibrium")


def test_unsupported_blocks_and_a_frictionless_arch_say_why_there_is_no_equilibrium(tmp_path):
    # each said "no equilibrium: the blocks cannot carry their own weight (the linear program is infeasible)"
    square = lambda y0: f"polygon = [[0, {y0}], [1, {y0}], [1, {y0 + 1}], [0, {y0 + 1}]]\n"  # noqa: E731
    ground = '[[support]]\nname = "ground"\npolygon = [[-1, -1], [2, -1], [2, 0], [-1, 0]]\n'
    stack = tmp_path / "stack.toml"
    stack.write_text(f'[[block]]\nname = "a"\n{square(0)}[[block]]\nname = "b"\n{square(1)}')
    assert_one_line_error(invoke("limit", stack), "no support: nothing holds the 2 blocks up")
    above = tmp_path / "above.toml"  # a stack of two hovering above a block on the ground
    above.write_text(
        f'[[block]]\nname = "a"\n{square(0)}[[block]]\nname = "b"\n{square(1.5)}[[block]]\nname = "c"\n{square(2.5)}'
        + ground
    )
    assert_one_line_error(
        invoke("limit", above), 'block 2 ("b") and the 1 block it touches rest on no support, so no equilibrium'
    )
    assert_one_line_error(invoke("limit", "arch", "--friction", "0"), "weight with friction 0 (the joints carry no")


def test_a_refusal_a_warning_explains_is_one_line_with_it(tmp_path):
    # a block touching nothing was said twice (a warning, then the error in its words); under a gravity
    # pointing up "no equilibrium" came with no reason on its line
    floating = tmp_path / "floating.toml"
    floating.write_text(
        '[[block]]\nname = "a"\npolygon = [[0, 1], [1, 1], [1, 2], [0, 2]]\n'
        '[[support]]\nname = "ground"\npolygon = [[-1, -1], [2, -1], [2, 0], [-1, 0]]\n'
    )
    assert_one_line_error(invoke("limit", floating), 'block 1 ("a") touches nothing: it has no support')
    up = tmp_path / "up.toml"
    up.write_text(
        "[run]\ngravity = [0.0, 9.81]\n[[block]]\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n"
        '[[support]]\nname = "ground"\npolygon = [[-1, -1], [2, -1], [2, 0], [-1, 0]]\n'
    )
    assert_one_line_error(invoke("limit", up), "no equilibrium", "([run] gravity = [0, 9.81] points up (y is up")


@pytest.mark.parametrize("gy", ["0.0", "-1e-300"])
def test_zero_gravity_is_one_line_exit_2(gy, tmp_path):
    # a scenario file may set gravity = [0, 0] (masonry run floats the blocks): limit ended in a
    # ZeroDivisionError traceback, exit 1; at 1e-300 m/s² it said "no equilibrium" for a block on the ground
    path = tmp_path / "space.toml"
    path.write_text(
        f"[run]\ngravity = [0.0, {gy}]\n[[block]]\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n"
        '[[support]]\nname = "ground"\npolygon = [[-1, -1], [2, -1], [2, 0], [-1, 0]]\n'
    )
    assert_one_line_error(invoke("limit", path), "gravity is zero or negligible", "λ times a weight")


# SIGTERM sent from inside the step named, in a real process (the default handler would kill pytest).
_SIGTERM_SCRIPT = """
import os, signal, sys, time
import masonrycli.limit.verify as verify
import masonrycli.recording.limit as recording

def sigterm():
    os.kill(os.getpid(), signal.SIGTERM)
    time.sleep(0.2)  # the handler runs here (or at once)

if sys.argv[1] == "recording":
    write = recording.write_limit_recording
    def write_limit_recording(*args):
        sigterm()
        write(*args)
    recording.write_limit_recording = write_limit_recording
else:
    def run_check(*args, **kwargs):
        sigterm()
        raise AssertionError("not stopped")
    verify.run_check = run_check
sys.argv = ["masonry", *sys.argv[2:]]
from masonrycli.cli.app import main
main()
"""


@pytest.mark.parametrize("during", ["recording", "verify"])
def test_sigterm_during_verify_says_so_exits_143_and_keeps_the_recording(during, column_file, tmp_path):
    """QA: SIGTERM during `limit --verify` exited -15 with no message. Now it goes the way of simulate and
    sweep: one line 'interrupted (SIGTERM): ...', exit 143, and the --out recording complete (a signal
    while it is written waits for it)."""
    import os
    import subprocess
    import sys

    from masonrycli.recording import inspect_recording

    out = tmp_path / "col.rrd"
    argv = ["limit", str(column_file), "--load", "tilt", "--verify", "--out", str(out)]
    proc = subprocess.run(
        [sys.executable, "-c", _SIGTERM_SCRIPT, during, *argv],
        capture_output=True,
        text=True,
        timeout=300,
        env=dict(os.environ, RERUN_ANALYTICS="0"),
    )
    assert proc.returncode == 143, (proc.returncode, proc.stdout, proc.stderr)
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("interrupted (SIGTERM): "), proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr and f"{out}" in lines[0]
    info = inspect_recording(out)
    assert info["complete"] and not info["truncated"] and info["has_blueprint"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["col.rrd"]  # no temporary file left


def test_ctrl_c_inside_numbas_compiler_is_the_interrupted_line(column_file, monkeypatch, capfd):
    """Walk-through, 2026-11-28: the analysis compiles the engine's contact detection on a first run; a Ctrl-C
    landing in one of numba's ctypes callbacks was dropped (a traceback) and the compile's RuntimeError
    came out as an internal error. Now: the one interrupted line, exit 130."""
    import signal

    import masonrycli.limit.command as command

    def compile_interrupted(scenario, live, **options):
        signal_inside_a_ctypes_callback(signal.SIGINT)
        raise RuntimeError("no compiled object yet for <Library '_narrowphase'>")

    monkeypatch.setattr(command, "analyse", compile_interrupted)
    result = invoke("limit", column_file)
    assert result.exit_code == 130, result.output
    assert words(result.output) == "interrupted: before λ was found; nothing was written"
    assert "Traceback" not in capfd.readouterr().err


def test_a_long_hinge_list_shows_the_fastest_turning_joints_first():
    # The aqueduct under a point load on v15 hinges 363 joints (|Δω| × length above 1e-4 of the fastest
    # point: the spandrel's running bond follows the arch). The table showed the first 8 in body order
    # (left-pier-c16-b1|left-pier-c17-b1, …), turning at 0.01–1 % of the crown hinge v15|v16, not shown.
    from masonrycli.limit.analysis import analyse
    from masonrycli.limit.problem import LiveLoad
    from masonrycli.scenario.builtin import builtin

    result = analyse(builtin("aqueduct"), LiveLoad("point", "-y", "v15"))
    u, j, m = result.solution.block_velocity, result.joints, result.model
    omega = np.append(u[:, 2], np.zeros(m.support_count))
    first, last = j.joint_start[:-1], j.joint_start[1:] - 1
    length = np.hypot(*(j.contact_point[last] - j.contact_point[first]).T)
    turn = np.abs(omega[j.joint_body[:, 1]] - omega[j.joint_body[:, 0]]) * length * (j.joint_points >= 2)
    turn = turn * result.motion.joint_hinged  # a face turning as it opens all along is no hinge (not listed)
    fastest = [result.names[k] for k in np.argsort(-turn, kind="stable")[:2]]
    assert fastest[0] == "v15|v16"  # the crown hinge under the load, as on the bare arch
    table = invoke("limit", "aqueduct", "--load", "point", "--block", "v15", "--direction", "-y").output
    shown = words(table.replace("│", " "))  # the list wraps within its cell
    assert f"{len(result.hinges)}, the 8 fastest: {', '.join(fastest)}" in shown, shown


def test_verify_headers_read_whole_at_80_columns(column_file, monkeypatch):
    # At 80 columns the headers were cut to "displacem…" and "similari…".
    monkeypatch.setenv("COLUMNS", "80")
    result = runner.invoke(app, ["limit", str(column_file), "--verify"], env={"COLUMNS": "80"})
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert max(len(line) for line in lines) <= 80
    start = next(k for k, line in enumerate(lines) if line.startswith("┏"))
    header = words(" ".join(lines[start + 1 : start + 3]).replace("┃", " "))
    assert "…" not in header, header
    for word in ("predicted", "largest", "move", "similarity", "hinges", "shared"):
        assert word in header.split(), header


def test_an_empty_out_is_said_to_be_empty():
    # Path("") is ".": "--out .: the file name must end in .rrd"
    from cli_helpers import assert_one_line_error, invoke

    assert_one_line_error(invoke("limit", "wall", "--out", ""), "--out", "the path is empty")


def test_a_built_in_takes_the_structure_options_of_masonry_build(tmp_path):
    """`masonry limit arch --span 8 --rise 2 …` analyses the arch `masonry build arch` writes with the same
    options (it said "No such option: --span": a bridge had to go through a GeoJSON file first)."""
    shape = ["--span", "8", "--rise", "2", "--ring-thickness", "0.5", "--pier-width", "3", "--pier-courses", "5"]
    geo = tmp_path / "bridge.geojson"
    assert invoke("build", "arch", *shape, "--out", geo).exit_code == 0
    direct = invoke("limit", "arch", *shape, "--json")
    assert direct.exit_code == 0, direct.output
    via_file = json.loads(invoke("limit", geo, "--json").stdout)
    default = json.loads(invoke("limit", "arch", "--json").stdout)
    data = json.loads(direct.stdout)
    assert data["blocks"] == via_file["blocks"] == 4 * 5 + 30 + 2
    assert data["load_factor"] == pytest.approx(via_file["load_factor"], rel=1e-9)
    assert data["hinges"] == via_file["hinges"] and data["load_factor"] != pytest.approx(default["load_factor"])
    thick = json.loads(invoke("limit", "arch", *shape, "--thickness", "4", "--json").stdout)
    assert thick["collapse_load_N"] == pytest.approx(4 * data["collapse_load_N"], rel=1e-9)


@pytest.mark.parametrize(
    "args, fragments",
    [
        (
            ["arch", "--blocks", "3"],
            [
                "--blocks: not an option of the arch (its options: --abutments, --density, --fill-cover, --fill-density, --fill-to, --pier-courses"
            ],
        ),
        (["aqueduct", "--rise", "1"], ["--rise: not an option of the aqueduct"]),
        (["wall", "--span", "8"], ["--span: not an option of the wall"]),
        (["arch", "--rise", "9"], ["--rise 9 m is more than half the span (1.8 m)"]),
    ],
)
def test_a_structure_option_the_built_in_does_not_take_is_one_line(args, fragments):
    assert_one_line_error(invoke("limit", *args), *fragments)


def test_structure_options_on_a_file_are_refused(column_file):
    assert_one_line_error(
        invoke("limit", column_file, "--span", "3"),
        "--span: structure options shape a built-in structure",
        "is a file, which gives its own geometry",
    )


def test_the_table_reads_lambda_as_an_acceleration_and_names_the_thickness_of_its_newtons(monkeypatch):
    """A horizontal body force λ × weight is a horizontal acceleration of λ g (what an engineer compares with
    a design PGA); the newtons are for the blocks' out-of-plane thickness (a 4 m wide bridge: 4 × a 1 m one)."""
    monkeypatch.setenv("COLUMNS", "250")  # one line a row
    data = json.loads(invoke("limit", "arch", "--json").stdout)
    lam = data["load_factor"]
    table = words(runner.invoke(app, ["limit", "arch", "--thickness", "4"], env={"COLUMNS": "250"}).output)
    assert f"a horizontal acceleration of {lam:.3g} g = {lam * 9.81:.3g} m/s²" in table
    assert "for blocks 4 m thick (out of plane)" in table and data["thickness_m"] == 1.0
    point = runner.invoke(app, ["limit", "arch", "--load", "point", "--block", "v10", "--direction", "-y"])
    point = words(point.output)
    assert "horizontal acceleration" not in point and "for blocks 1 m thick" in point


def test_a_point_load_placed_by_abscissa_loads_the_voussoir_over_it_and_points_down():
    """`--at X`: the top block over x = X (a deck load at the quarter span), found here from the ring's
    definition (R = (s²/4 + f²)/(2f), equal angles); a point load's default direction is down (it was +x)."""
    span, rise, ring, n = 8.0, 2.0, 0.5, 30
    shape = ["--span", "8", "--rise", "2", "--ring-thickness", "0.5", "--pier-width", "3", "--pier-courses", "5"]
    radius = (span**2 / 4 + rise**2) / (2 * rise)
    alpha = np.arcsin(span / (2 * radius))
    extrados_x = -(radius + ring) * np.sin(alpha - 2 * alpha * np.arange(n + 1) / n)
    k = int(np.searchsorted(extrados_x, -span / 4)) - 1  # the voussoir whose extrados spans x = -2
    data = json.loads(invoke("limit", "arch", *shape, "--load", "point", "--at", "-2", "--json").stdout)
    assert data["load"] == {
        "kind": "point",
        "direction": "-y",
        "block": f"v{k + 1:02d}",
        "at_m": -2.0,
        "force_N": None,
        "worst": False,
        "spread_deg": None,
        "spread_onto": None,
    }
    named = json.loads(invoke("limit", "arch", *shape, "--load", "point", "--block", f"v{k + 1:02d}", "--json").stdout)
    down = invoke("limit", "arch", *shape, "--load", "point", "--block", f"v{k + 1:02d}", "--direction", "-y", "--json")
    assert named["load_factor"] == json.loads(down.stdout)["load_factor"]  # --block: down, at its centroid
    # --at: at x = -2 on its extrados, not its centroid (the λ against the four-hinge reference:
    # test_limit_ring_mechanisms.test_a_deck_load_at_x_acts_on_the_extrados_there)
    assert data["load_factor"] != pytest.approx(named["load_factor"], rel=1e-3)
    table = runner.invoke(app, ["limit", "arch", *shape, "--load", "point", "--at", "-2"], env={"COLUMNS": "250"})
    assert f"point load on v{k + 1:02d} (the top block over x = -2 m, loaded there), -y" in table.output


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--at", "-1"], "--at -1: only a point load acts at one place (use --load point)"),
        (["--load", "point", "--at", "-1", "--block", "v05"], "--block v05 and --at -1: give the loaded block one way"),
        (["--load", "point", "--at", "50"], "--at 50: no block over x = 50 m (the blocks span x = -2.7 … 2.7 m)"),
    ],
)
def test_a_bad_at_is_one_line(args, fragment):
    assert_one_line_error(invoke("limit", "arch", *args), fragment)


def test_thrust_gives_each_abutments_least_and_greatest_thrust_of_the_classical_arch(tmp_path):
    """`--thrust`: the semicircle of t/R = 0.15 on rigid springers against the classical statics of the
    continuous arch (tests/test_limit_arch.py: H_min/W = 0.175873 with the supports spreading, H_max/W =
    0.226976 pushed together; Heyman 1982, Ochsendorf 2006), each springer pushed outward."""
    path = tmp_path / "semicircle.toml"
    path.write_text(dump_scenario(semicircular_arch(0.15, 60, friction=2.0)))
    data = json.loads(invoke("limit", path, "--thrust", "--json").stdout)
    weight = data["reference_load_N"]  # the horizontal load's reference: the arch's weight
    by_support = {t["support"]: t for t in data["support_thrust"]}
    assert by_support["right-springer"]["direction"] == "+x" and by_support["left-springer"]["direction"] == "-x"
    for t in by_support.values():
        assert t["least_N"] / weight == pytest.approx(0.175873, rel=5e-3)
        assert t["greatest_N"] / weight == pytest.approx(0.226976, rel=5e-3)
    table = words(runner.invoke(app, ["limit", str(path), "--thrust"], env={"COLUMNS": "250"}).output)
    assert f"thrust on left-springer │ {by_support['left-springer']['least_N']:.4g} …" in table
    assert json.loads(invoke("limit", path, "--json").stdout)["support_thrust"] is None  # only when asked


def test_the_recordings_panel_reads_lambda_as_the_table_does():
    from masonrycli.limit import LiveLoad, analyse
    from masonrycli.limit.command import resolve_structure
    from masonrycli.limit.drawing import mechanism_document

    result = analyse(resolve_structure("arch", None, {"thickness": 4.0}), LiveLoad("horizontal"))
    text = mechanism_document(result)
    lam = result.load_factor
    assert (
        f"**load factor λ = {lam:.4f}** (a horizontal acceleration of {lam:.3g} g = {lam * 9.81:.3g} m/s²; tilt ψ"
        in text
    )
    assert "N, for blocks 4 m thick (out of plane) (the resultant of the body forces" in text


def test_the_settle_hint_is_not_given_where_settling_cannot_mend_it(tmp_path):
    # a built-in's stones are laid exact and a setting's warning gives its own reason: the hint that a traced
    # wall's stones may be drawn apart ('--settle 0.5') ended 'limit arch --friction 0' and a gravity pointing up
    arch = invoke("limit", "arch", "--friction", "0")
    assert_one_line_error(arch, "with friction 0 (the joints carry no shear)")
    up = tmp_path / "up.toml"
    up.write_text(
        "[run]\ngravity = [0.0, 9.81]\n[[block]]\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n"
        '[[support]]\nname = "ground"\npolygon = [[-1, -1], [2, -1], [2, 0], [-1, 0]]\n'
    )
    for result in (arch, invoke("limit", up)):
        assert "--settle" not in result.output, result.output
    thin = tmp_path / "thin.toml"  # drawn by hand: the hint stays
    thin.write_text(
        '[material]\nfriction = 2.0\n[[block]]\nname = "leaning"\npolygon = [[0, 0], [1, 0], [1, 1], [0, 1]]\n'
        '[[support]]\nname = "ground"\npolygon = [[-1, -1], [0.3, -1], [0.3, 0], [-1, 0]]\n'
    )
    assert_one_line_error(invoke("limit", thin), "no equilibrium", "--settle 0.5")
