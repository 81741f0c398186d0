"""What a grasp in a :class:`~bayesgrasp.world.World` returns: the grasp's contacts, one grasp
(:class:`WorldGrasp`) and a batch (:class:`WorldGraspBatch`), each with ``to_dict``."""
from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional, Tuple

import numpy as np

@dataclass(frozen=True)
class ContactRecord:
    """One contact of a :class:`WorldGrasp` (plain Python values, world frame)."""

    point: List[float]     # on the object's (or the table's) surface (m)
    normal: List[float]    # the object's outward unit normal (+z for the table)
    link: int              # hand link index (0 = palm)
    link_name: str
    penetration: float     # >= 0 (m)
    on_table: bool
    triangle: int = -1             # the object's triangle (row of its faces); -1 for the table
    part: Optional[str] = None     # the triangle's part name, when the object has part labels

    def to_dict(self) -> dict:
        return {"point": self.point, "normal": self.normal, "link": self.link, "link_name": self.link_name,
                "penetration": self.penetration, "on_table": self.on_table, "triangle": self.triangle,
                "part": self.part}


@dataclass(frozen=True)
class WorldGrasp:
    """One grasp tried in a :class:`World` (see :meth:`World.grasp`, :meth:`World.approach`,
    :meth:`World.grasp_pose`)."""

    joint_angles: np.ndarray          # (J,) closed joint angles (rad)
    contacts: List[ContactRecord]
    epsilon: float                    # GWS epsilon on the object contacts (0 when collision_at_start)
    volume: float                     # GWS volume
    collision_at_start: bool          # the open hand started in collision (no grasp)
    hand_pose: np.ndarray             # (4, 4) world pose of the hand while closing
    lifted: Optional[bool] = None     # lift-test verdict (None unless lifted)
    lift_displacement: Optional[float] = None  # m, the lift test's displacement
    stopped_by_table: bool = False    # the approach stopped on the table without touching the object
    hand_pose_object: Optional[np.ndarray] = None  # (4, 4) the same pose in the object frame
    joint_names: Tuple[str, ...] = ()  # names of the entries of joint_angles

    def to_dict(self) -> dict:
        """The grasp as a dict of these fields (contacts as dicts)."""
        return {"joint_angles": self.joint_angles, "contacts": [c.to_dict() for c in self.contacts],
                "epsilon": self.epsilon, "volume": self.volume, "collision_at_start": self.collision_at_start,
                "hand_pose": self.hand_pose, "lifted": self.lifted, "lift_displacement": self.lift_displacement,
                "stopped_by_table": self.stopped_by_table, "hand_pose_object": self.hand_pose_object,
                "joint_names": list(self.joint_names)}


@dataclass(frozen=True)
class WorldGraspBatch:
    """N grasps tried in a :class:`World` (see :meth:`World.grasp_batch`,
    :meth:`World.approach_batch`, :meth:`World.grasp_poses`); row i = grasp i."""

    joint_angles: np.ndarray        # (N, J)
    contacts: object                # sim BatchContacts: point, normal, link, penetration, on_table, triangle,
                                    # grasp, offsets
    epsilon: np.ndarray             # (N,) GWS epsilon (0 when collision_at_start)
    volume: np.ndarray              # (N,) GWS volume
    collision_at_start: np.ndarray  # (N,) bool
    hand_pose: np.ndarray           # (N, 4, 4) world poses of the hand while closing
    link_contact: np.ndarray        # (N, L) bool
    table_contact: np.ndarray       # (N, L) bool
    distance_queries: np.ndarray    # (N,) FCL distance calls
    lifted: Optional[np.ndarray] = None             # (N,) bool when lift-tested, else None
    lift_displacement: Optional[np.ndarray] = None  # (N,) m when lift-tested, else None
    stopped_by_table: Optional[np.ndarray] = None   # (N,) bool
    hand_pose_object: Optional[np.ndarray] = None   # (N, 4, 4) the hand poses in the object frame
    joint_names: Tuple[str, ...] = ()               # names of the columns of joint_angles
    contact_part: Optional[np.ndarray] = None       # (K,) part name per contact (None on the table), or
                                                    # None when the object has no part labels

    def __len__(self) -> int:
        return len(self.epsilon)

    def contact_records(self, i: int, link_names) -> List[ContactRecord]:
        """Grasp i's contacts as records (``link_names``: the hand's links, for their names)."""
        c = self.contacts
        offsets = getattr(c, "offsets", None)     # a single grasp's contacts have none: all are grasp 0's
        lo, hi = (0, len(c.link)) if offsets is None else (int(offsets[i]), int(offsets[i + 1]))
        part = (lambda k: None) if self.contact_part is None else (lambda k: self.contact_part[k])
        return [ContactRecord(c.point[k].tolist(), c.normal[k].tolist(), int(c.link[k]), link_names[int(c.link[k])],
                              float(c.penetration[k]), bool(c.on_table[k]), int(c.triangle[k]), part(k))
                for k in range(lo, hi)]
