"""masonrycli/cli/option_values.py as a user meets it: choices in any case, a "~" the shell left. Numbers
and paths refused as bad input: bad_input_options.py, bad_input_paths.py."""

from __future__ import annotations

from cli_helpers import invoke


def test_choice_options_take_any_case_and_help_lists_the_lower_case(tmp_path):
    # "sweep --im PGV" said "--im PGV: expected one of pga, pgv, arias, sa"; "limit --load Tilt",
    # "--direction -X", "--outcome Sliding" and "--solver NLGS" likewise
    r = invoke("limit", "wall", "--load", "Tilt", "--direction", "-X", "--json")
    assert r.exit_code == 0, r.output
    r = invoke("simulate", "wall", "--solver", "NLGS", "--duration", "0.01", "--no-recording")
    assert r.exit_code == 0, r.output
    out = tmp_path / "s.csv"
    sweep = ("sweep", "wall", "-p", "amp=0.1,0.2", "--find", "amp", "--outcome", "Sliding", "--im", "PGV")
    r = invoke(*sweep, "--duration", "0.05", "--workers", "0", "--no-recording", "-o", out)
    assert r.exit_code == 0, r.output
    assert "pga, pgv, arias, sa" in invoke("sweep", "--help").output


def test_a_tilde_the_shell_left_is_the_home_folder(tmp_path, monkeypatch):
    # "--out=~/runs/w.rrd" (no expansion after "=") made a folder named "~" in the working folder and wrote
    # there; --history and build --out alike.
    home, work = tmp_path / "home", tmp_path / "work"
    work.mkdir()
    (home / "runs").mkdir(parents=True)
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(work)
    result = invoke("simulate", "wall", "--duration", 0.01, "--out=~/runs/w.rrd", "--history=~/runs/w.npz")
    assert result.exit_code == 0, result.output
    assert invoke("build", "wall", "--out=~/runs/w.geojson").exit_code == 0
    assert sorted(p.name for p in (home / "runs").iterdir()) == ["w.geojson", "w.npz", "w.rrd"]
    assert list(work.iterdir()) == []
