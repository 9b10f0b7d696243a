"""Recompute the figures quoted in docs/scenarios.md from the runs' history files.

Run the five scenarios of docs/scenarios.md with ``--history X.npz``, then, from the repository root::

    python docs/scenario_figures.py --wall wall51.npz --wall wall248.npz --arch arch.npz \\
        --aqueduct aqueduct.npz --aqueduct aqueduct-shaken.npz \\
        [--static wall51-static.npz --static wall248-static.npz]

Any subset of the options works; each prints its tables (plain text, numbers as quoted in the doc).
``--static`` takes the history of the same wall with the ground at rest (``masonry simulate wall
--amp 0 --duration 0.01 --record-every 1 --history ...``) for the exact check of σ_yy per course.

Joint states are read from the history: ``block_max_opening`` (the widest opening of the block's initial
face joints — body pairs with two initial contact points — followed kinematically by
``masonrycli.analysis.mechanism``; single corner contacts are left out), ``block_sliding_ratio`` (share of the block's
normal contact load carried by sliding contacts: at the friction limit *and* sliding faster than
``masonrycli.analysis.mechanism.SLIP_SPEED``, 1 mm/s) and ``joint_hinged``. Two things the history does not hold
per joint — which end of a joint is open (intrados / extrados) and how far its faces have slid — are
measured geometrically, which also gives an independent cross-check of the openings and hinges: the
structure is rebuilt with the project's builder (defaults, ``blocks`` = N for a wall; checked against the
recorded initial centroids), the two end points of every joint face of ``joint_body`` are attached to both
bodies, and each end's opening is the normal separation of the two copies, (p_b − p_a)·n_a, with the rigid
motions of ``block_q`` / ``support_q``. Positive = open, negative = interpenetration. The script prints how
far the widest geometric opening of each block is from ``block_max_opening``.

The colour ranges of the recording are replayed from the history the way the recorder follows the data
(``masonrycli.recording.colour_range.RangeTracker`` over every frame after the initial one).

This script is the command line; the tables come from its sibling modules: figures_history.py (loading,
joint geometry, tables, cross-checks), figures_wall.py, figures_arch.py and figures_arch_response.py.
"""

from __future__ import annotations

import argparse

import numpy as np

# sibling modules of docs/scenario_figures.py: its folder is first on sys.path when it runs as a script
from figures_arch import arch
from figures_wall import wall


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wall", action="append", default=[], help="history of a wall run (repeatable)")
    ap.add_argument(
        "--static",
        action="append",
        default=[],
        help="history of the same wall at rest, in the order of --wall (optional)",
    )
    ap.add_argument("--arch", action="append", default=[], help="history of an arch run")
    ap.add_argument("--aqueduct", action="append", default=[], help="history of an aqueduct run")
    args = ap.parse_args(argv)
    np.seterr(invalid="ignore", divide="ignore")  # NaN strains (blocks in no triangle) are expected
    np.set_printoptions(linewidth=160)
    for i, w in enumerate(args.wall):
        wall(w, args.static[i] if i < len(args.static) else None)
    for a in args.arch:
        arch(a, "arch")
    for a in args.aqueduct:
        arch(a, "aqueduct")


if __name__ == "__main__":
    main()
