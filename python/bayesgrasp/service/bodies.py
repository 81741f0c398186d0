"""The request bodies, as pydantic models (they make the OpenAPI description): unknown fields
are refused, names are plain words (a server path is never taken from a client)."""
from __future__ import annotations

from typing import Dict, List, Optional, Union

from pydantic import BaseModel, ConfigDict, Field

from ..arm import DEFAULT_BASE
from ..loop.context import RunContext
from ..loop.episode import EpisodeSettings

NAME = r"^[A-Za-z0-9][A-Za-z0-9_-]{0,63}$"      # built-in objects, hands, categories, tasks, methods
OBJECT = NAME[:-1] + r"(/[0-9]{1,4})?$"           # a built-in object, or a category member (mug/3)
Triple = List[float]


class _Body(BaseModel):
    model_config = ConfigDict(extra="forbid")


class Planning(_Body):
    """What a plan is made from: the object (pose uncertainty: a built-in ``object`` at the
    ``estimate`` x, y, yaw) or a category task (``category``, ``task`` and the view: ``cloud`` +
    ``viewpoint``, or the simulated view of built-in ``object`` at ``object_pose``); ``robot``: the
    arm the hand is on (a category task's grasps are the ones it reaches)."""

    object: Optional[str] = Field(None, pattern=OBJECT, description="built-in object name (cylinder, mug/3)")
    estimate: Optional[Triple] = Field(None, min_length=3, max_length=3, description="x, y (m), yaw (rad)")
    method: Optional[str] = Field(None, pattern=NAME, description="stability | explore; with a category: laplace, "
                                                                    "regularised, gaussian, baseline or fusion")
    category: Optional[str] = Field(None, pattern=NAME)
    task: Optional[str] = Field(None, pattern=NAME)
    object_pose: Triple = Field([0.0, 0.0, 0.0], min_length=3, max_length=3)
    cloud: Optional[List[Triple]] = Field(None, description="the object's points in the table frame (m)")
    viewpoint: Optional[Triple] = Field(None, min_length=3, max_length=3, description="the camera centre (m)")
    exclude: Optional[List[str]] = None
    seed: int = Field(0, ge=0, le=2**63 - 1)
    hand: str = Field(RunContext.hand, pattern=NAME[:-1] + r"(\.urdf)?$", description="built-in hand name")
    models: Dict[str, Union[int, float, bool, str, None, List[float]]] = Field(
        default_factory=dict, description="ModelSettings overrides (as --set models.FIELD=VALUE)")
    planner: Dict[str, Union[int, float, bool, str, None, List[float]]] = Field(
        default_factory=dict, description="PlannerSettings overrides (as --set planner.FIELD=VALUE)")
    robot: Optional[str] = Field(None, pattern=NAME, description="built-in arm the hand is on (as --robot); "
                                                                 "default: none, the hand is free-floating")
    robot_base: List[float] = Field(list(DEFAULT_BASE), min_length=4, max_length=4,
                                    description="the arm's root in the table frame: x, y, z (m), yaw (rad)")
    flange: Optional[str] = Field(None, pattern=NAME, description="the link the hand is mounted on (as --flange)")
    mount: Optional[List[float]] = Field(None, min_length=6, max_length=6,
                                         description="the palm in the flange's frame: x, y, z (m), roll, pitch, "
                                                     "yaw (rad) (as --mount)")


class NewEpisode(Planning):
    """``bayesgrasp episode new``'s options; ``id``: the client's name for the episode (a retry
    with the same id and body returns the same episode), else one is made."""

    id: Optional[str] = Field(None, description="episode id (checked by the service's id pattern)")
    attempts: int = Field(EpisodeSettings.attempts, ge=1, le=1000)


class Observation(_Body):
    """What the robot read after executing ``next``: every hand joint (the grasp's joint names and
    units), whether the object came up, and the client's id of this request (a retry with the
    same id is answered again, not applied twice)."""

    joints: List[float]
    lifted: Union[bool, str]
    request_id: str = Field(description="the client's id of this request (checked by the service's id pattern)")
