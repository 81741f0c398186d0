"""The endpoints. Every episode call holds the episode's lock; an observation is recorded under
its request id before it is applied and its reply after (:mod:`bayesgrasp.loop.outside_requests`),
and the reply leaves only once both are on disk."""
from __future__ import annotations

import secrets
import shutil

import numpy as np
from fastapi import APIRouter, Request
from fastapi.responses import JSONResponse

from .. import __version__
from ..loop.outside_loop import STATE_FILE, EpisodeError, check_joints, check_lifted
from ..loop.outside_requests import RequestLog, body_digest, sync_directory
from .bodies import NewEpisode, Observation, Planning
from .errors import ApiError
from .security import check_id
from .start import category_answer, first_grasp, start_episode
from .store import Warm

router = APIRouter(prefix="/v1")
CREATE = "(create)"   # the request log's entry of the episode's creation (no client id can spell it)


def _store(request: Request):
    return request.app.state.store


def episode_reply(eid: str, ep) -> dict:
    """What a step answers: the episode, its status and the next grasp (None when it ended)."""
    return {"id": eid, "kind": ep.kind, "status": ep.state["status"], "attempts_made": len(ep.state["steps"]),
            "next": ep.next}


@router.get("/health")
def health(request: Request) -> dict:
    return {"status": "ok", "bayesgrasp": __version__, "episodes_warm": _store(request).warm_count()}


@router.post("/episodes", status_code=201)
def new_episode(body: NewEpisode, request: Request):
    """Starts an episode (the options of ``bayesgrasp episode new``) and answers its first grasp."""
    store = _store(request)
    eid = check_id(body.id) if body.id else secrets.token_hex(8)
    digest = body_digest(body.model_dump(exclude={"id"}))
    with store.lock(eid):
        d = store.directory(eid)
        if (d / STATE_FILE).is_file():
            warm = store.get(eid)
            record = warm.log.get(CREATE)
            if not (body.id and record and record["digest"] == digest):
                raise ApiError(409, "episode_exists", f"episode {eid!r} exists (started with another body)")
            if record["reply"] is None:                   # created before a crash; the reply was not recorded
                warm.log.finish(CREATE, episode_reply(eid, warm.episode))
            return JSONResponse(warm.log.get(CREATE)["reply"], status_code=200)   # a retried creation
        fresh = not d.exists()
        log = RequestLog(d)
        with store.creating:
            log.begin(CREATE, digest, 0)
            try:
                ep = start_episode(d, body, store.cache_dir)
            except BaseException:
                if fresh:
                    shutil.rmtree(d, ignore_errors=True)      # a failed call leaves nothing
                else:
                    log.drop(CREATE)
                raise
        sync_directory(d)
        warm = Warm(ep, log, ())
        warm.written()
        store.put(eid, warm)
        reply = episode_reply(eid, ep)
        log.finish(CREATE, reply)
    return reply


def _reading(ep, joints) -> np.ndarray:
    """The robot's joints as our joint vector (a URDF hand's are in the URDF's names and units)."""
    hand = ep.hand
    if hand.urdf_joint_map is None:
        return check_joints(joints, hand)
    if len(joints) != len(hand.urdf_joint_map):
        raise EpisodeError(f"joints: {hand.name}'s URDF has {len(hand.urdf_joint_map)} moving joints, got "
                           f"{len(joints)} values")
    try:
        return check_joints(hand.joints_from_urdf(np.asarray(joints, float)), hand)
    except ValueError as e:
        raise EpisodeError(f"joints: {e}") from None


@router.post("/episodes/{eid}/observations")
def observe(eid: str, body: Observation, request: Request):
    """The robot executed ``next``: its joints and the lift verdict; answers the next grasp (or
    the end). A request id seen before gets the reply it got then, and changes nothing."""
    store = _store(request)
    check_id(eid)
    rid = check_id(body.request_id, "request_id")
    digest = body_digest(body.model_dump())
    with store.lock(eid):
        warm = store.get(eid)
        ep, log = warm.episode, warm.log
        record = log.get(rid)
        steps = len(ep.state["steps"])
        if record is not None:
            if record["digest"] != digest:
                raise ApiError(409, "request_id_reused", f"request_id {rid!r} was used for another observation")
            if record["reply"] is not None:
                return record["reply"]
            if steps == record["steps_before"] + 1:       # applied before a crash; the reply was not recorded
                reply = episode_reply(eid, ep)
                log.finish(rid, reply)
                return reply
            if steps != record["steps_before"]:
                raise ApiError(409, "reply_lost", f"request {rid!r} was applied and later steps followed; its reply "
                                                  "is lost")
        if ep.finished:
            raise ApiError(409, "episode_finished", f"episode {eid!r} is finished ({ep.state['status']}); "
                                                    "nothing to observe")
        q = _reading(ep, body.joints)
        lifted = check_lifted(body.lifted)
        if record is None:
            log.begin(rid, digest, steps)
        try:
            ep.observe(q, lifted)
        except BaseException:
            if len(ep.state["steps"]) == steps:
                log.drop(rid)                             # nothing was applied
            raise
        sync_directory(ep.directory)
        warm.written()
        reply = episode_reply(eid, ep)
        log.finish(rid, reply)
    return reply


@router.get("/episodes/{eid}")
def show(eid: str, request: Request) -> dict:
    """The episode's history and belief (``bayesgrasp episode show --json``)."""
    store = _store(request)
    with store.lock(check_id(eid)):
        ep = store.get(eid).episode
        st = ep.state
        doc = {"id": eid, "kind": ep.kind, "method": st["method"], "status": st["status"], "steps": st["steps"],
               "next": ep.next, "belief": ep.belief()}
        doc.update({k: st[k] for k in ("object", "estimate", "category", "task") if k in st})
    return doc


@router.post("/plan")
def plan(body: Planning, request: Request) -> dict:
    """One question, no episode: the first grasp a pose episode with these options would plan
    (``{next}``), or with ``category`` and ``task`` what ``bayesgrasp category --json`` prints
    (its ``grasp`` the task grasp)."""
    store = _store(request)
    if body.category or body.task:
        with store.creating:                 # the registrations and task grasps are loaded once, shared
            return category_answer(body, store.cache_dir)
    return {"next": first_grasp(body, store.cache_dir)}
