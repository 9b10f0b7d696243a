"""One recorded frame: everything the history file and the recording receive every ``record_every`` steps.

Plain arrays (struct of arrays). Index conventions: blocks 0..N-1 in scenario order, supports 0..S-1,
contacts 0..C-1 (C varies per frame). Body indices in ``contact_body`` run over blocks first, then
supports (body N + s is support s).

Two configurations: the blocks' ``block_q`` / ``block_v`` are the state at the end of the step (``time``); the
``contact_*`` arrays are the contacts of that step, detected and solved in the step's intermediate configuration
of the Moreau–Jean scheme, q_m = q_n + (1 − θ)·dt·v_n = ``block_q − θ·dt·block_v`` (engine/integrate.py,
engine/solver.py), and the block stress of ``tensors`` takes its centroids G there (run.py gives the tensors
``body_q_m``). A block's stress computed from the contacts with G = ``block_q[:, :2] − θ·dt·block_v[:, :2]`` is
the engine's to rounding (2e-15 relative); with the end-of-step ``block_q`` it is off by ~1e-4 relative on a
shaken wall (tests/test_frame_configuration.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from masonrycli.engine.contact import ContactStatus

CONTACT_OPEN, CONTACT_STICK, CONTACT_SLIP = ContactStatus.OPEN, ContactStatus.STICK, ContactStatus.SLIP


@dataclass(frozen=True, eq=False)
class Frame:
    """The state of a run at one recorded step (module doc); arrays are float64 unless stated."""

    step: int
    """Time-step index (0 = initial state)."""
    time: float
    """Simulated time, s."""
    block_q: np.ndarray
    """(N, 3) centroid x, y (m) and rotation from the initial orientation (rad, counter-clockwise), at the end of
    the step; the contacts are at ``block_q − θ·dt·block_v`` (module doc)."""
    block_v: np.ndarray
    """(N, 3) centroid velocity vx, vy (m/s) and angular velocity (rad/s)."""
    support_q: np.ndarray
    """(S, 3) support displacement-carrying pose: reference point x, y (m) and rotation (rad)."""
    support_v: np.ndarray
    """(S, 2) imposed support velocity, m/s."""
    support_force: np.ndarray
    """(S, 2) total contact force the blocks exert on each support, N (per block thickness)."""
    contact_body: np.ndarray
    """(C, 2) int: bodies a, b of each contact (normal points from a to b)."""
    contact_point: np.ndarray
    """(C, 2) contact point in world coordinates, m, in the step's intermediate configuration q_m (module doc),
    not at ``block_q``."""
    contact_normal: np.ndarray
    """(C, 2) unit normal from body a to body b."""
    contact_force: np.ndarray
    """(C, 2) contact force on body b in world coordinates, N (impulse / dt); body a gets the opposite."""
    contact_gap: np.ndarray
    """(C,) gap at detection, m (negative = penetration)."""
    contact_status: np.ndarray
    """(C,) int8 :class:`~masonrycli.engine.contact.ContactStatus`: 0 open, 1 stick, 2 slip."""
    contact_mobilised: np.ndarray
    """(C,) |r_t| / (mu r_n), 0 for open contacts."""
    tensors: dict
    """Per-block tensor fields, name -> array (see masonrycli.analysis.tensors.TENSOR_FIELDS)."""
    energy_kinetic: float
    """J (per block thickness)."""
    energy_potential: float
    """J, relative to y = 0 along gravity."""
    energy_dissipated: float
    """J, cumulated since t = 0 (>= 0)."""
    support_work: float
    """J, cumulated work done by the supports on the blocks since t = 0."""
    nlgs_iterations: int
    """Sweeps of the step that ended at this frame (masonrycli.engine.dispatch.solve)."""
    nlgs_residual: float
    """m/s: RMS contact-law violation of that step's last sweep, the quantity compared with the tolerance."""
    contact_count: int
    """C, the step's contacts (the length of the ``contact_*`` arrays)."""
    joint_body: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int64))
    """(J, 2) bodies of each joint (pairs touching along a face initially; see masonrycli.analysis.mechanism)."""
    joint_hinged: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    """(J,) True where the joint is hinged: one end carries all the normal force, the other is open."""
    hinge_point: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    """(H, 2) m: the loaded contact point of each hinged joint (the hinge), world coordinates."""
    nlgs_unconverged: int = 0
    """Steps since t = 0 (up to this frame) whose solve did not meet its tolerance before the sweep cap."""
