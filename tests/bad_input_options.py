"""Bad-input catalogue rows about the command line's options: run / check / simulate / build, sweep and limit
(the paths it names, to write or to read: bad_input_paths.py). Each row is (id, files, argv, exit code, fragment); tests/test_bad_input_catalogue.py runs them.
"""

from __future__ import annotations

from bad_input_files import scen

WALL = ("simulate", "wall", "--duration", "0.01")
ARCH = ("simulate", "arch", "--duration", "0.01")
RUN = ("run", "s.toml")

# (id, files, argv, exit code, fragment of the one line)
OPTION_ROWS = [
    # -- every option of run / check / simulate / build
    ("opt-dt", {**scen()}, (*RUN, "--dt", "-1", "--no-recording"), 2, "--dt: dt = -1: must be > 0"),
    ("opt-dt-text", {**scen()}, (*RUN, "--dt", "abc"), 2, "--dt abc: must be a number"),
    ("opt-duration", {**scen()}, (*RUN, "--duration", "0", "--no-recording"), 2, "--duration: duration = 0"),
    (
        "opt-duration-dt-steps",
        {**scen()},
        (*RUN, "--duration", "1e5", "--dt", "1e-4", "--no-recording"),
        2,
        "--duration and --dt: duration = 1e5 at dt = 1e-4 is 1,000,000,000 steps (at most 100,000,000)",
    ),
    (
        "opt-dt-not-dividing",
        {**scen()},
        (*RUN, "--dt", "0.3", "--no-recording"),
        2,
        "--dt: duration = 1.0 is not a whole number of steps of dt = 0.3",
    ),
    (  # one step of 1e-310 s ran, then the summary overflowed (t / dt): an OverflowError traceback
        "opt-dt-subnormal",
        {**scen()},
        (*RUN, "--duration", "1e-310", "--dt", "1e-310", "--no-recording"),
        2,
        "--dt: dt = 1e-310: must be >= 1e-09 s (a likely typo)",
    ),
    ("opt-theta", {**scen()}, (*RUN, "--theta", "0.2", "--no-recording"), 2, "--theta: theta = 0.2"),
    ("opt-friction", {**scen()}, (*RUN, "--friction", "nan", "--no-recording"), 2, "--friction: friction = nan"),
    (
        "opt-record-every",
        {**scen()},
        (*RUN, "--record-every", "0", "--no-recording"),
        2,
        "--record-every: record_every = 0",
    ),
    ("opt-tolerance", {**scen()}, (*RUN, "--tolerance", "1", "--no-recording"), 2, "--tolerance: tolerance = 1"),
    (  # every step ran to the 100 000-sweep cap
        "opt-tolerance-tiny",
        {**scen()},
        (*RUN, "--tolerance", "1e-300", "--no-recording"),
        2,
        "--tolerance: tolerance = 1e-300: must be >= 1e-15 m/s (float64 resolves a 1 m/s velocity to",
    ),
    ("scenario-tolerance-tiny", {**scen("tolerance = 1e-16")}, ("check", "s.toml"), 2, "tolerance = 1e-16: must be >="),
    (
        "opt-max-iterations",
        {**scen()},
        (*RUN, "--max-iterations", "0", "--no-recording"),
        2,
        "--max-iterations: max_iterations = 0",
    ),
    (
        "opt-solver",
        {**scen()},
        (*RUN, "--solver", "gs", "--no-recording"),
        2,
        '--solver: solver = "gs": must be one of',
    ),
    ("opt-unknown", {**scen()}, (*RUN, "--bogus"), 2, "No such option: --bogus"),
    # it said "(masonry simulate --help lists the options)" of a subcommand
    (
        "cmd-unknown",
        {},
        ("simulate", "tower"),
        2,
        "simulate --help lists the commands)",
    ),
    # walk-through 2026-11-28: an option missing its value pointed to "masonry --help" (no --duration there)
    (
        "opt-without-value",
        {},
        (*WALL, "--duration"),
        2,
        "Option '--duration' requires an argument. (masonry simulate wall --help lists the options)",
    ),
    (
        "opt-without-value-run",
        {**scen()},
        (*RUN, "--dt"),
        2,
        "Option '--dt' requires an argument. (masonry run --help lists the options)",
    ),
    ("check-opt-dt", {**scen()}, ("check", "s.toml", "--dt", "-1"), 2, "--dt: dt = -1"),
    ("sim-density", {}, (*WALL, "--density", "-5", "--no-recording"), 2, "--density: density = -5"),
    ("sim-thickness", {}, (*WALL, "--thickness", "0", "--no-recording"), 2, "--thickness: thickness = 0"),
    ("sim-blocks", {}, (*WALL, "--blocks", "0", "--no-recording"), 2, "--blocks 0: must be a positive integer"),
    (
        "sim-blocks-impossible",
        {},
        (*WALL, "--blocks", "51", "--courses", "5", "--no-recording"),
        2,
        # named as typed ('builder "wall": …' named the builder's keys, not the options)
        "error: --blocks and --courses: 51 blocks cannot be laid in running bond with 5 courses",
    ),
    (
        "sim-length",
        {},
        (*WALL, "--courses", "8", "--length", "10", "--no-recording"),
        2,
        "length 10 m is not a whole number of 0.3 m blocks",
    ),
    ("sim-courses", {}, (*WALL, "--courses", "0", "--no-recording"), 2, "courses"),
    (
        "sim-block-length",
        {},
        (*WALL, "--block-length", "-0.3", "--no-recording"),
        2,
        "error: --block-length -0.3: must be a positive",
    ),
    (
        "sim-settlement-wall",
        {},
        (*WALL, "--settlement", "0.01", "--no-recording"),
        2,
        ": the wall stands on one ground",
    ),
    (
        "sim-settlement-negative",
        {},
        (*ARCH, "--settlement", "-1", "--no-recording"),
        2,
        "--settlement -1: must be >= 0",
    ),
    # "--amp 1" alone said "--settlement with --amp" (the settlement was the default, not given)
    (
        "sim-amp-on-settling-arch",
        {},
        (*ARCH, "--amp", "1", "--no-recording"),
        2,
        "--amp 1: the arch settles its right foundation by default; shake both foundations with --settlement 0",
    ),
    (
        "sim-settlement-and-amp",
        {},
        (*ARCH, "--settlement", "0.01", "--amp", "1", "--no-recording"),
        2,
        "--settlement 0.01 with --amp 1",
    ),
    # these two ran: the frequency of no sine was ignored without a word
    ("sim-freq-on-settling-arch", {}, (*ARCH, "--freq", "3", "--no-recording"), 2, "--freq 3: the arch settles"),
    (
        "sim-freq-without-amp",
        {},
        ("simulate", "aqueduct", "--settlement", "0", "--freq", "3", "--duration", "0.01", "--no-recording"),
        2,
        "--freq 3 without --amp: nothing shakes the aqueduct (give --amp A)",
    ),
    # it said "velocity = [0.0, nan]: must be finite numbers" (no option)
    (
        "sim-settlement-nan",
        {},
        (*ARCH, "--settlement", "nan", "--no-recording"),
        2,
        "--settlement nan: must be a finite",
    ),
    ("sim-amp-nan", {}, (*WALL, "--amp", "nan", "--no-recording"), 2, "--amp: amplitude = nan: must be"),
    ("sim-freq-negative", {}, (*WALL, "--freq", "-1", "--no-recording"), 2, "--freq: frequency = -1: must be"),
    (
        "sim-voussoirs",
        {},
        (*ARCH, "--voussoirs", "1", "--no-recording"),
        2,
        "error: --voussoirs 1: must be an integer ≥ 2",
    ),
    ("sim-span", {}, (*ARCH, "--span", "-1", "--no-recording"), 2, "error: --span -1: must be a positive number"),
    # a float option's value echoed as typed: these said "= 0.0", "= 2.0"
    ("sim-dt-zero", {}, (*WALL, "--dt", "0", "--no-recording"), 2, "--dt: dt = 0: must be > 0"),
    ("sim-theta-two", {}, (*WALL, "--theta", "2", "--no-recording"), 2, "--theta: theta = 2: must be <= 1"),
    # the builder's name once (it read "error: wall: wall: block count ...")
    (
        "build-blocks",
        {},
        ("build", "wall", "--blocks", "0", "--out", "w.geojson"),
        2,
        "error: --blocks 0: must be a positive integer",
    ),
    (
        "build-density",
        {},
        ("build", "wall", "--density", "1e9", "--out", "w.geojson"),
        2,
        "--density: density = 1e9: must be between 0.001 and 100000 kg/m³",
    ),
    (
        "sim-block-height",
        {},
        (*WALL, "--block-height", "0", "--no-recording"),
        2,
        "error: --block-height 0: must be a positive number",
    ),
    (
        "sim-pier-courses",
        {},
        (*ARCH, "--pier-courses", "0", "--no-recording"),
        2,
        "error: --pier-courses 0: must be an integer ≥ 1",
    ),
    (
        "sim-ring-thickness",
        {},
        (*ARCH, "--ring-thickness", "-1", "--no-recording"),
        2,
        "error: --ring-thickness -1: must be a positive number",
    ),
    (
        "sim-ring-thickness-absurd",
        {},
        (*ARCH, "--ring-thickness", "0.0001", "--no-recording"),
        2,
        "error: --ring-thickness 0.0001 m is absurd (a likely typo: 0.001 to 1000 m)",
    ),
    (
        "sim-pier-width",
        {},
        (*ARCH, "--pier-width", "0", "--no-recording"),
        2,
        "error: --pier-width 0: must be a positive",
    ),
    (
        "sim-wall-courses",
        {},
        ("simulate", "aqueduct", "--wall-courses", "0", "--no-recording"),
        2,
        "error: --wall-courses 0: must be",
    ),
    ("sim-record-missing", {}, (*WALL, "--record", "nope.at2", "--no-recording"), 2, "nope.at2: cannot read record"),
    # it was ignored without a word (the magnified shape is drawn in the recording only)
    ("sim-magnify-no-recording", {}, (*WALL, "--magnify", "5", "--no-recording"), 2, "--magnify 5 with --no-recording"),
    ("sim-scale-alone", {}, (*WALL, "--scale", "2", "--no-recording"), 2, "--scale 2 goes with --record"),
    (
        "sim-baseline-alone",
        {},
        (*WALL, "--baseline", "none", "--no-recording"),
        2,
        "--baseline none goes with --record",
    ),
    (
        "sim-baseline-word",
        {"a.csv": "time (s),acc (m/s2)\n0,0\n0.01,1\n"},
        (*WALL, "--record", "a.csv", "--baseline", "off", "--no-recording"),
        2,
        'error: --baseline off: must be "quadratic" or "none"',
    ),
    # an absurd support speed ran to exit 0 ("collapsed at t = 0.001 s"; the CSV with numpy's overflow warnings)
    ("sim-amp-absurd", {}, (*WALL, "--amp", "1e30", "--no-recording"), 2, 'support "ground": sine 1e+30 m/s'),
    ("sim-settlement-absurd", {}, (*ARCH, "--settlement", "1e9", "--no-recording"), 2, "up to 1e+09 m/s, more than"),
    (
        "sim-record-absurd",
        {"huge.csv": "0,1e300\n1,-1e300\n"},
        (*WALL, "--record", "huge.csv", "--no-recording"),
        2,
        "record of velocity (huge.csv, 2 samples, 0–1 s) along (1, 0) moves at up to 1e+300 m/s",
    ),
    (  # read as velocity in m/s without a word
        "sim-record-displacement",
        {"d.csv": "time (s),disp (m)\n0,0.1\n1,0\n"},
        (*WALL, "--record", "d.csv", "--no-recording"),
        2,
        'd.csv:1: the header says displacement ("time (s),disp (m)") but a record is read as velocity (m/s) or',
    ),
    (
        "limit-load",
        {},
        ("limit", "arch", "--load", "bogus"),
        2,
        "--load bogus: expected one of horizontal, tilt, point",
    ),
    ("limit-direction", {}, ("limit", "arch", "--direction", "up"), 2, "--direction up: expected one of +x, -x"),
    ("limit-point-no-block", {}, ("limit", "arch", "--load", "point"), 2, "--load point: name the loaded block"),
    ("limit-friction", {}, ("limit", "arch", "--friction", "-1"), 2, "--friction: friction = -1: must be >= 0"),
    # --block '' was taken as no block: a horizontal load ran as if it was not given (--block v01 is refused)
    ("limit-block-empty", {}, ("limit", "arch", "--block", ""), 2, "--block '': an empty name"),
    # a blank name was said '--block  : only a point load acts on one block' ('--block  : no such block' with --load point)
    ("limit-block-blank", {}, ("limit", "arch", "--load", "point", "--block", " "), 2, "--block ' ': an empty name"),
    # an empty extra word (a quoted shell variable with nothing in it) was an IndexError, exit 1, a traceback
    ("simulate-empty-word", {}, ("simulate", "wall", ""), 2, "extra argument(s) (): an empty word"),
    ("limit-empty-word", {}, ("limit", "wall", ""), 2, "extra argument(s) (): an empty word"),
    ("build-blank-word", {}, ("build", "wall", "--out", "w.geojson", " "), 2, "extra argument(s) ( ): an empty word"),
]
