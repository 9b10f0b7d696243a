"""masonry export: a history as CSV. The values against plain formulas on hand-built histories (a known
motion), the CSV read back with the csv module, a real run through the command line checked against the
physics of a wall sliding on its ground and the momentum balance, and bad input as one line, exit 2."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from masonrycli.outputs.export import export_table, frame_rate

from cli_helpers import assert_one_line_error, invoke

G = 9.81


def read_csv(path) -> dict[str, list[str]]:
    """The CSV's columns by header name (cells as text)."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    assert all(len(row) == len(rows[0]) for row in rows)
    return {name: [row[i] for row in rows[1:]] for i, name in enumerate(rows[0])}


def floats(cells) -> np.ndarray:
    return np.array([float(c) if c else np.nan for c in cells])


# the hand-built history: two blocks side by side ("a" 100 kg at x = -0.15, "b" 300 kg at x = 0.15, both
# centroids at y = 0.1, 0.2 m high) and a third "c" on top (y = 0.3); a ground moving at constant velocity
# D; every block moving with the constant acceleration C (x) from rest; frames at uneven times
C, D = 2.0, 0.5
TIMES = np.array([0.0, 0.01, 0.02, 0.03, 0.035])
MASS = np.array([100.0, 300.0, 50.0])
X0 = np.array([-0.15, 0.15, 0.0])
Y0 = np.array([0.1, 0.1, 0.3])


def hand_history(path, status="completed", **extra):
    t = TIMES
    T, N = len(t), 3
    q = np.zeros((T, N, 3))
    q[:, :, 0] = X0 + 0.5 * C * t[:, None] ** 2
    q[:, :, 1] = Y0
    v = np.zeros((T, N, 3))
    v[:, :, 0] = C * t[:, None]
    support_q = np.zeros((T, 1, 3))
    support_q[:, 0, 0] = D * t
    support_q[:, 0, 1] = -0.25
    support_v = np.zeros((T, 1, 2))
    support_v[:, 0, 0] = D
    force = np.zeros((T, 1, 2))
    force[:, 0, 0] = -MASS.sum() * C  # the blocks push the ground back as it drives them
    force[:, 0, 1] = -MASS.sum() * G
    arrays = dict(
        time=t,
        step=np.arange(T) * 10,
        block_q=q,
        block_v=v,
        support_q=support_q,
        support_v=support_v,
        support_force=force,
        block_name=np.array(["a", "b", "c"]),
        support_name=np.array(["ground"]),
        hinge_count=np.array([0, 0, 1, 2, 2]),
        energy_kinetic=np.linspace(0, 1, T),
        block_mass=MASS,
        block_inertia=np.array([1.0, 2.0, 0.5]),
        block_extent=np.array([[-0.3, 0.0, 0.0, 0.2], [0.0, 0.0, 0.3, 0.2], [-0.15, 0.2, 0.15, 0.4]]),
        status=np.asarray(status),
        note=np.asarray("" if status == "completed" else f"{status} at t = 0.0350 s (step 35 of 100)"),
        run=np.asarray(json.dumps({"gravity_m_s2": [0.0, -G]})),
    )
    np.savez(path, **(arrays | extra))
    return path


def test_a_known_motion_is_exported_as_the_formulas_say(tmp_path):
    h = hand_history(tmp_path / "h.npz")
    table = export_table(h, blocks=["c"], course_numbers=[1], top=True)
    col = dict(zip(table.names, table.values))
    t = TIMES
    for target in ("c", "course 1", "top"):
        assert np.allclose(col[f"{target} ux rel (m)"], 0.5 * C * t**2 - D * t, rtol=0, atol=1e-15), target
        assert np.allclose(col[f"{target} vx rel (m/s)"], C * t - D, rtol=0, atol=1e-15)
        # velocity linear in time: the finite difference is exact, even across the uneven last interval
        assert np.allclose(col[f"{target} ax rel (m/s2)"], C, rtol=0, atol=1e-12)
        assert np.all(col[f"{target} uy rel (m)"] == 0) and np.all(col[f"{target} rot (rad)"] == 0)
    assert np.array_equal(col["ground ux (m)"], D * t) and np.allclose(col["ground ax (m/s2)"], 0)
    # drift: the top ("c") relative to the ground over the blocks' height, 0.4 m
    assert np.allclose(col["drift ratio (-)"], (0.5 * C * t**2 - D * t) / 0.4, rtol=0, atol=1e-15)
    # step 0 (the first frame) is before any contact force: empty cells, not a 0 that reads as a force
    assert np.isnan(col["base shear (N)"][0]) and np.isnan(col["base vertical (N)"][0])
    assert np.allclose(col["base shear (N)"][1:], MASS.sum() * C) and np.allclose(col["base vertical (N)"][1:], 450 * G)
    # about O = (0, 0) moving with the ground: the weights' lever arms, less the mass's inertia at its height
    lever = MASS * (X0 + 0.5 * C * t[:, None] ** 2 - D * t[:, None])
    moment = G * lever.sum(axis=1) - C * (MASS * Y0).sum()
    # the same reaction's moment: empty where the shear is (step 0), the formula's from the first solved step on
    assert np.isnan(col["overturning moment (N m)"][0])
    assert np.allclose(col["overturning moment (N m)"][1:], moment[1:], rtol=1e-12)
    assert col["hinges (-)"].dtype.kind == "i" and list(col["hinges (-)"]) == [0, 0, 1, 2, 2]
    absolute = dict(zip(*(lambda tb: (tb.names, tb.values))(export_table(h, blocks=["a"], relative=False))))
    assert np.allclose(absolute["a ux (m)"], 0.5 * C * t**2) and np.allclose(absolute["a vx (m/s)"], C * t)


def test_accelerations_are_central_differences_of_the_recorded_velocities():
    t = np.array([0.0, 0.1, 0.2, 0.3, 0.45])
    v = t**3
    expected = [
        (v[1] - v[0]) / 0.1,
        (v[2] - v[0]) / 0.2,
        (v[3] - v[1]) / 0.2,
        (v[4] - v[2]) / 0.25,
        (v[4] - v[3]) / 0.15,
    ]
    assert np.allclose(frame_rate(v, t), expected, rtol=1e-14)
    assert np.isnan(frame_rate(np.array([1.0]), np.array([0.0]))).all()


def test_the_csv_reads_back_the_same_numbers_every_kth_row(tmp_path):
    h = hand_history(tmp_path / "h.npz")
    result = invoke("export", h, "--blocks", "a,b", "--every", 2)
    assert result.exit_code == 0, result.output
    cols = read_csv(tmp_path / "h.csv")  # the default name: beside the history
    table = export_table(h, blocks=["a", "b"])
    assert list(cols) == table.names and cols["hinges (-)"] == ["0", "1", "2"]
    for name, value in zip(table.names, table.values):
        assert np.array_equal(floats(cols[name]), value[::2], equal_nan=True), name
    assert list(cols)[:3] == ["time (s)", "ground ux (m)", "ground uy (m)"] and "a ax rel (m/s2)" in cols
    assert floats(cols["time (s)"]).tolist() == [0.0, 0.02, 0.035]


def test_an_interrupted_history_is_exported_and_said(tmp_path):
    h = hand_history(tmp_path / "i.npz", status="interrupted")
    result = invoke("export", h, "--out", tmp_path / "i.csv")
    assert result.exit_code == 0, result.output
    assert "interrupted at t = 0.0350 s (step 35 of 100): exported its 5 frames, up to t = 0.035 s" in " ".join(
        result.output.split()
    )
    assert len(read_csv(tmp_path / "i.csv")["time (s)"]) == 5


def test_an_old_history_without_block_extent_estimates_the_course_height(tmp_path):
    h = tmp_path / "old.npz"
    with np.load(hand_history(tmp_path / "h.npz")) as npz:
        arrays = {k: npz[k] for k in npz.files if k not in ("block_extent", "block_mass", "block_inertia")}
    np.savez(h, **arrays)
    table = export_table(h, course_numbers=[1, 2])
    col = dict(zip(table.names, table.values))
    assert "overturning moment (N m)" not in col and "course 2 ux rel (m)" in col
    # centroids 0.1 and 0.3: course height 0.2, height 0.2 + 0.2
    assert np.allclose(col["drift ratio (-)"], (0.5 * C * TIMES**2 - D * TIMES) / 0.4)
    assert any("course height estimated from the centroids, 0.2 m" in note for note in table.notes)
    # README: "the moment is left out, and a note says so"
    assert any("no overturning moment (no block masses)" in note for note in table.notes)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A real run of the default wall (1 m/s at 2 Hz), every step recorded, and its history."""
    folder = tmp_path_factory.mktemp("export")
    path = folder / "w.npz"
    result = invoke("simulate", "wall", "--duration", 0.02, "--record-every", 1, "--history", path, "--no-recording")
    assert result.exit_code == 0, result.output
    return path


def test_a_real_run_exported_through_the_command_line(run, tmp_path):
    out = tmp_path / "w.csv"
    result = invoke("export", run, "--out", out, "--blocks", "c06-b04", "--course", 1, "--top")
    assert result.exit_code == 0, result.output
    cols = read_csv(out)
    h = np.load(run)
    names = [str(n) for n in h["block_name"]]
    q, ground = h["block_q"], h["support_q"][:, 0, 0] - h["support_q"][0, 0, 0]
    assert np.array_equal(floats(cols["time (s)"]), h["time"])
    k = names.index("c06-b04")
    assert np.allclose(floats(cols["c06-b04 ux rel (m)"]), q[:, k, 0] - q[0, k, 0] - ground, rtol=0, atol=1e-15)
    # the courses by name: c01-… the lowest, c06-… the top
    for label, prefix in (("course 1", "c01-"), ("top", "c06-")):
        members = [i for i, n in enumerate(names) if n.startswith(prefix)]
        mean = (q[:, members, 0] - q[0, members, 0]).mean(axis=1) - ground
        assert np.allclose(floats(cols[f"{label} ux rel (m)"]), mean, rtol=0, atol=1e-15), label
    # physics: the wall slides on its ground from the first step (1.28 g > μ g): base shear = μ × weight
    shear, vertical = floats(cols["base shear (N)"]), floats(cols["base vertical (N)"])
    assert np.allclose(shear[1:], 0.6 * vertical[1:], rtol=1e-4)
    # the first row (step 0, no contact force solved yet): the base reaction's three cells are empty together,
    # so a moment-against-shear plot has no point there (its moment was a number beside an empty shear)
    assert [cols[c][0] for c in ("base shear (N)", "base vertical (N)", "overturning moment (N m)")] == ["", "", ""]
    assert all(cols["overturning moment (N m)"][1:])
    # the sign: the momentum balance of step k, Σ m (v_k − v_{k−1}) = dt × (the supports' force on the blocks)
    dt, mass = 0.001, h["block_mass"]
    momentum = (mass * h["block_v"][:, :, 0]).sum(axis=1)
    assert np.allclose(np.diff(momentum) / dt, shear[1:], rtol=1e-6)
    # central differences of the momentum: the mean of two steps' base shear, as the overturning moment uses them
    ax = frame_rate(h["block_v"][:, :, 0], h["time"])
    assert np.allclose((mass * ax).sum(axis=1)[1:-1], 0.5 * (shear[1:-1] + shear[2:]), rtol=1e-6)
    assert floats(cols["drift ratio (-)"])[-1] == pytest.approx(
        ((q[-1, -9:, 0] - q[0, -9:, 0]).mean() - ground[-1]) / 1.2, rel=1e-12
    )


def test_bad_input_is_one_line(run, tmp_path):
    out = tmp_path / "x.csv"
    assert_one_line_error(
        invoke("export", run, "--out", out, "--blocks", "c07-b04"),
        "--blocks c07-b04: no such block in",
        "w.npz (51 blocks: c01-b01 … c06-b09); did you mean c06-b04?",
    )
    assert_one_line_error(invoke("export", run, "--out", out, "--course", 9), "--course 9:", "has 6 courses")
    assert_one_line_error(invoke("export", run, "--out", out, "--course", "x"), "--course x: not a course number")
    assert_one_line_error(invoke("export", run, "--out", out, "--ground", "table"), "--ground table: no such support")
    assert_one_line_error(invoke("export", run, "--out", out, "--every", 0), "--every 0")
    assert_one_line_error(invoke("export", run, "--out", tmp_path / "x.txt"), "must end in .csv")
    assert not out.exists()
    out.write_text("mine")
    assert_one_line_error(invoke("export", run, "--out", out), f"--out {out}: the file exists (add --force")
    assert out.read_text() == "mine"
    assert invoke("export", run, "--out", out, "--force").exit_code == 0 and out.read_text().startswith("time (s),")
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    assert_one_line_error(invoke("export", tmp_path / "other.npz"), "other.npz: a NumPy archive (.npz) but not a run")
    assert_one_line_error(invoke("export", tmp_path / "none.npz"), "none.npz: no such history")
    (tmp_path / "text.npz").write_text("time,a\n")
    assert_one_line_error(invoke("export", tmp_path / "text.npz"), "text.npz: not a readable history")
    np.savez(tmp_path / "bare.npz", time=np.zeros(2))
    assert_one_line_error(invoke("export", tmp_path / "bare.npz"), "bare.npz: a history without block_q")


class SupportMoment:
    """A frame sink: the moment about O of the support contacts' forces on the blocks, from the solver's
    contact points and forces (what the export's Newton–Euler moment must reproduce without them)."""

    def __init__(self, n: int, base: tuple[float, float]):
        self.n, self.base, self.moments, self.q0 = n, np.array(base), [], None

    def on_frame(self, frame) -> None:
        if self.q0 is None:
            self.q0 = frame.support_q[0, :2].copy()
        origin = self.base + frame.support_q[0, :2] - self.q0
        total = 0.0
        for (a, b), point, force in zip(frame.contact_body, frame.contact_point, frame.contact_force):
            if (a < self.n) == (b < self.n):
                continue  # block against block (their forces cancel), or support against support
            on_block = force if b < self.n else -force  # contact_force acts on body b
            r = point - origin
            total += r[0] * on_block[1] - r[1] * on_block[0]
        self.moments.append(total)

    def close(self, status: str = "completed", note: str = "") -> None:
        pass


def test_the_overturning_moment_is_that_of_the_support_contacts(tmp_path):
    from masonrycli.outputs.history import History, block_constants
    from masonrycli.run import Simulation, simulate
    from masonrycli.scenario.builtin import builtin

    scenario = builtin("wall", duration=0.02, record_every=1)
    sim = Simulation(scenario)
    constants = block_constants(sim.model)
    extent = constants["block_extent"]
    watch = SupportMoment(sim.model.block_count, (0.5 * (extent[:, 0].min() + extent[:, 2].max()), extent[:, 1].min()))
    history = History(sim.model.block_name, sim.model.support_name)
    simulate(scenario, [history, watch], sim=sim)
    path = tmp_path / "h.npz"
    np.savez(path, **(history.arrays() | constants))
    table = export_table(path)
    moment = dict(zip(table.names, table.values))["overturning moment (N m)"]
    contacts = np.array(watch.moments)
    # frame k's accelerations are means over steps k and k+1: so is the contacts' moment
    mean = 0.5 * (contacts[1:-1] + contacts[2:])
    assert np.abs(mean).min() > 2e4  # the wall, dragged at 12 m/s², leans on its ground: tens of kN m
    # 3.4e-4 at most: the export's lever arms are the frame's, the step's impulses act mid-step
    assert np.allclose(moment[1:-1], mean, rtol=1e-3), np.abs(moment[1:-1] / mean - 1).max()


def test_a_folder_of_histories_gives_one_csv_each(tmp_path):
    folder = tmp_path / "histories"
    folder.mkdir()
    hand_history(folder / "amp=0.5.npz")
    hand_history(folder / "amp=1.npz", status="interrupted")
    out = tmp_path / "csv"
    out.mkdir()
    result = invoke("export", folder, "--out", out, "--blocks", "c")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["amp=0.5.csv", "amp=1.csv"]
    assert floats(read_csv(out / "amp=1.csv")["c ax rel (m/s2)"]) == pytest.approx([C] * 5)
    assert "amp=1.npz: interrupted at t = 0.0350 s" in " ".join(result.output.split())
    # nothing is written unless every CSV can be: one exists already
    (out / "amp=0.5.csv").unlink()
    assert_one_line_error(invoke("export", folder, "--out", out), "--out", "amp=1.csv: the file exists")
    assert not (out / "amp=0.5.csv").exists()
    assert_one_line_error(
        invoke("export", folder / "amp=0.5.npz", folder / "amp=1.npz", "--out", tmp_path / "one.csv"),
        "one.csv: several histories, one CSV each: --out names a folder for them",
    )
    made = tmp_path / "made" / "csv"  # a folder not there yet is made, as one file's folder is
    assert invoke("export", folder / "amp=0.5.npz", folder / "amp=1.npz", "--out", made).exit_code == 0
    assert sorted(p.name for p in made.iterdir()) == ["amp=0.5.csv", "amp=1.csv"]
    assert invoke("export", folder / "amp=0.5.npz", folder / "amp=1.npz").exit_code == 0  # beside each
    assert sorted(p.name for p in folder.glob("*.csv")) == ["amp=0.5.csv", "amp=1.csv"]
    # nor when a later history cannot be exported: one without the --blocks name, one of no frame
    mixed = tmp_path / "mixed"
    mixed.mkdir()
    hand_history(mixed / "a.npz")
    hand_history(mixed / "b.npz", block_name=np.array(["x", "y", "z"]))
    assert_one_line_error(invoke("export", mixed, "--blocks", "c"), "--blocks c: no such block in", "b.npz")
    hand_history(mixed / "b.npz", time=TIMES[:0])
    assert_one_line_error(invoke("export", mixed), "b.npz: a history of no frame")
    assert list(mixed.glob("*.csv")) == []
    empty = tmp_path / "empty"
    empty.mkdir()
    assert_one_line_error(invoke("export", empty), "empty: a folder without histories (*.npz)")
