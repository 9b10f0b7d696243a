"""Rigid-block limit analysis: the collapse load factor and mechanism of any block assembly.

One linear program on the engine's own contacts (Livesley 1978; Gilbert & Melbourne 1994), solved by
HiGHS: :func:`analyse` → :class:`LimitResult`. Modules: ``joints`` (contacts grouped per pair),
``problem`` (the LP and its dual), ``kinematics`` (hinges and sliding joints of the mechanism),
``thrust`` (line of thrust), ``verify`` (the same structure run by the NSCD engine near λ).
"""

from masonrycli.limit.analysis import LimitResult, analyse, analyse_model
from masonrycli.limit.problem import LimitError, LiveLoad

__all__ = ["LimitError", "LimitResult", "LiveLoad", "analyse", "analyse_model"]
