"""The per-step trace of one lift test as numpy arrays, and a plot of it.

``LiftTester.run(pose, joints, trace_every=k)`` records every k steps (and the last step) the
time, the object's pose in the palm frame, the joint angles, the phalanx each finger's motor
drives (> 0 after breakaway) and every hand-object contact::

    r = tester.run(pose, joints, trace_every=4)
    tr = LiftTrace.from_core(r.trace)
    plot_lift_trace(tr, "lift.png")   # displacement, joints, normal force per link vs time
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import List

import numpy as np

__all__ = ["LiftTrace", "plot_lift_trace"]


@dataclass
class LiftTrace:
    """One lift test's trace (S samples, C contacts in all).

    Attributes:
        time: (S,) s.
        object_pose: (S, 4, 4) the object (centre of mass, principal axes) in the palm frame.
        reference_pose: (4, 4) the same after the squeeze (the displacement's reference).
        joints: (S, J) joint angles, rad (HandModel layout).
        driven: (S, F) int, the phalanx each finger's motor drives (0: no breakaway).
        contact_sample: (C,) int, the sample of each contact.
        contact_link: (C,) int, HandModel link index (0: palm and knuckles).
        contact_point: (C, 3) m, world frame, on the hand link.
        contact_normal: (C, 3) unit, out of the object.
        contact_force: (C,) N, normal force.
        link_names: the hand's link names (indexed by contact_link).
        phase_ends: (3,) s, the end of the squeeze, the lift and the shake.
    """

    time: np.ndarray
    object_pose: np.ndarray
    reference_pose: np.ndarray
    joints: np.ndarray
    driven: np.ndarray
    contact_sample: np.ndarray
    contact_link: np.ndarray
    contact_point: np.ndarray
    contact_normal: np.ndarray
    contact_force: np.ndarray
    link_names: List[str]
    phase_ends: np.ndarray

    @classmethod
    def from_core(cls, t) -> "LiftTrace":
        """From the core's ``LiftTrace`` (``LiftResult.trace``)."""
        return cls(np.asarray(t.time, float), np.asarray(t.object_pose, float), np.asarray(t.reference_pose, float),
                   np.asarray(t.joints, float), np.asarray(t.driven, int), np.asarray(t.contact_sample, int),
                   np.asarray(t.contact_link, int), np.asarray(t.contact_point, float).reshape(-1, 3),
                   np.asarray(t.contact_normal, float).reshape(-1, 3), np.asarray(t.contact_force, float),
                   list(t.link_names), np.asarray(t.phase_ends, float))

    @property
    def displacement(self) -> np.ndarray:
        """(S,) m, the object's centre of mass in the palm frame against the reference."""
        return np.linalg.norm(self.object_pose[:, :3, 3] - self.reference_pose[:3, 3], axis=1)

    def link_force(self) -> np.ndarray:
        """(S, L) N, the total normal force on each hand link per sample."""
        out = np.zeros((len(self.time), len(self.link_names)))
        np.add.at(out, (self.contact_sample, self.contact_link), self.contact_force)
        return out

    def fingers_in_contact(self, finger_links: List[List[int]]) -> np.ndarray:
        """(S,) int, how many fingers (each a list of its link indices) touch the object per sample."""
        touching = self.link_force() > 0
        return np.sum([touching[:, links].any(axis=1) for links in finger_links], axis=0)


def plot_lift_trace(trace: LiftTrace, path) -> None:
    """Displacement, joint angles and per-link normal force against time, the phases shaded;
    written to ``path`` (PNG)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    edges = [0.0, *trace.phase_ends, max(trace.time[-1], trace.phase_ends[-1])]
    for a in ax:
        for i, (t0, t1) in enumerate(zip(edges[:-1], edges[1:])):
            a.axvspan(t0, t1, color=f"C{i}", alpha=0.08, lw=0)
    ax[0].plot(trace.time, 100 * trace.displacement, "k")
    ax[0].axhline(2.0, color="r", ls="--", lw=0.8)
    ax[0].set_ylabel("displacement (cm)")
    for j in range(1, trace.joints.shape[1]):
        ax[1].plot(trace.time, np.degrees(trace.joints[:, j]), label=f"joint {j}")
    ax[1].set_ylabel("joint angle (deg)")
    ax[1].legend(fontsize=7, ncol=3)
    force = trace.link_force()
    for k in np.flatnonzero(force.max(axis=0) > 0):
        ax[2].plot(trace.time, force[:, k], label=trace.link_names[k])
    ax[2].set_ylabel("normal force (N)")
    ax[2].set_xlabel("time (s): squeeze | lift | shake | hold")
    ax[2].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
