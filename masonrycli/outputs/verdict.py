"""A run's verdict in words: its state, peak drift and hinged joints as the run's summary says them, and as
``masonry report`` and ``masonry inspect H.npz`` say them again from a history's ``result_*`` arrays.

Plain functions of numbers, without the engine: ``masonry inspect`` reads a history in a fraction of a
second and must not load numba to word a row (importing :mod:`masonrycli.run` costs a second more).
"""

from __future__ import annotations

RESULT_KEYS = ("state", "collapse_time", "collapse_reason", "peak_drift", "residual_drift", "max_opening")
RESULT_KEYS += ("max_displacement", "hinges")
"""The keys of :func:`masonrycli.run.run_outcome` a history keeps (``result_<key>``): what the summary's
state and peak drift rows say, which the frames alone cannot give again (the peak is watched every step).
Here, not in :mod:`masonrycli.outputs.history` (which imports the engine's kernels, numba): inspect reads them."""


def describe_outcome(outcome: dict) -> str:
    """``collapsed at t = 0.53 s (a block fell ...)``, ``damaged (residual drift 0.31 %, 2 hinges, ...)``."""
    tail = (
        f"residual drift {shown(100 * outcome['residual_drift'])} % of the height, {outcome['hinges']} hinges, "
        f"largest opening {shown(1000 * outcome['max_opening'])} mm"
    )
    if "max_displacement" in outcome:  # a block moved off its place damages too: the line shows by how much
        tail += f", largest block displacement {shown(1000 * outcome['max_displacement'])} mm"
    if outcome["state"] == "collapsed":
        return f"collapsed at t = {outcome['collapse_time']:.3f} s ({outcome['collapse_reason']})"
    return f"{outcome['state']} ({tail})"


def describe_most_open(name: str, opening: float, at: tuple[float, float], origin=None) -> str:
    """``v05's joints, 3.88 mm; its centroid at (2.31, 5.02) m (on the map (650002.31, 6861005.02))``: where the
    largest opening is, on the survey too when its file was read moved from a map grid (``origin``, m)."""
    text = f"{name}'s joints, {shown(1000 * opening)} mm; its centroid at ({at[0]:.3f}, {at[1]:.3f}) m"
    if origin is not None:
        text += f" (on the map ({at[0] + origin[0]:.3f}, {at[1] + origin[1]:.3f}))"
    return text


def describe_hinges(pairs: list[str]) -> str:
    """``12: c01-b01|c02-b01, …``: how many joints are hinged, and the first 8 by name (the summary's row and
    ``masonry report``'s)."""
    named = ", ".join(pairs[:8]) + (" …" if len(pairs) > 8 else "")
    return f"{len(pairs)}" + (f": {named}" if pairs else "")


def describe_peak_drift(ratio: float, height: float) -> str:
    """``0.0627 % of the height (1.88 mm over 3 m), the top's largest horizontal move relative to the ground
    during the run``: an intact wall's residual drift is ~0 whatever it went through (a 3 m section at 0.25 g
    ended at 0.00396 % having swung to 0.063 %)."""
    return (
        f"{shown(100 * ratio)} % of the height ({shown(1000 * ratio * height)} mm over {height:.3g} m), the top's "
        "largest horizontal move relative to the ground during the run"
    )


def describe_residual_drift(ratio: float, height: float) -> str:
    """``0.115 % of the height (1.38 mm)``: the top's drift relative to the ground at the end."""
    return f"{shown(100 * ratio)} % of the height ({shown(1000 * ratio * height)} mm)"


def shown(value: float) -> str:
    """3 significant digits, and 0 below 1e-6 (% or mm): a wall at rest read 'residual drift 2.16e-17 % ...,
    largest opening 1.67e-32 mm', round-off dressed as a measurement."""
    return "0" if abs(value) < 1e-6 else f"{value:.3g}"


def counted(n: int, word: str) -> str:
    """``1 run``, ``2 runs``, ``0 rows``: a count and its noun, plural unless one ("1 runs" was said)."""
    return f"{n} {word}{'' if n == 1 else 's'}"
