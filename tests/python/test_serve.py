"""`bayesgrasp serve` as a robot's stack meets it: the real server in a subprocess on a free loopback
port. An episode driven through the API equals the in-process loop (what `plan` runs) and the
`bayesgrasp episode` command bit for bit, on the same files; every refusal is a JSON error with its
code and changes nothing; a retried observation is applied once; a server killed with SIGKILL in
the middle of an observation and restarted loses and repeats nothing.

The objects are the cylinder with the default model settings, whose models ship with the package."""
import json
import os
import signal
import ssl
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import httpx
import numpy as np
import pytest

from bayesgrasp.client import Client, ServiceError
from bayesgrasp.loop.context import RunContext
from bayesgrasp.loop.episode import EpisodeSettings, execute, run_episode
from bayesgrasp.service.security import load_or_create_token
from bayesgrasp.world import World
from testkit import cli_json, free_port

OBJ, TRUTH, EST, SEED = "cylinder", [0.01, -0.01, 0.4], [0.035, -0.04, 0.9], 3
TOKEN = "test-token-0123456789abcdef"
START_SECONDS = 120


class Server:
    """``bayesgrasp serve`` in a subprocess (this process's environment: the same core and path)."""

    def __init__(self, episodes, token_file, port=None, extra=(), verify=True):
        self.port = port or free_port()
        self.url = f"{'https' if '--certfile' in extra else 'http'}://127.0.0.1:{self.port}"
        self.episodes, self.token_file = episodes, token_file
        self.log = open(episodes.parent / f"server-{self.port}.log", "ab")
        self.proc = subprocess.Popen([sys.executable, "-m", "bayesgrasp.cli", "serve", "--port", str(self.port),
                                      "--episodes", str(episodes), "--token-file", str(token_file), *extra],
                                     env=dict(os.environ), stdout=self.log, stderr=subprocess.STDOUT)
        deadline = time.time() + START_SECONDS
        while True:
            assert self.proc.poll() is None, self.output()
            try:
                if httpx.get(self.url + "/v1/health", timeout=2, verify=verify).status_code == 401:
                    break
            except httpx.TransportError:
                pass
            assert time.time() < deadline, "the server did not start: " + self.output()
            time.sleep(0.2)

    def output(self) -> str:
        self.log.flush()
        return (self.episodes.parent / f"server-{self.port}.log").read_text(errors="replace")

    def kill(self):
        self.proc.send_signal(signal.SIGKILL)
        self.proc.wait(30)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.kill()
        self.log.close()


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    d = tmp_path_factory.mktemp("serve")
    (d / "token").write_text(TOKEN + "\n")
    s = Server(d / "episodes", d / "token")
    yield s
    s.stop()


@pytest.fixture(scope="module")
def client(server):
    return Client(server.url, TOKEN)


def new_body(method, attempts, **kw):
    return {**dict(object=OBJ, estimate=EST, method=method, attempts=attempts, seed=SEED), **kw}


def drive(client, body):
    """An episode through the API, the simulator executing each grasp at the truth (the robot)."""
    ctx = RunContext()
    models = ctx.models(OBJ)
    robot = World.single(OBJ, pose=TRUTH, hand=ctx.hand)
    doc = client.new_episode(**body)
    replies = [doc]
    while doc["next"] is not None:
        ex = execute(robot, models, np.array(doc["next"]["top_grasp"]), np.array(TRUTH), ctx)
        doc = client.observe(doc["id"], ex.joint_angles.tolist(), ex.lifted)
        replies.append(doc)
    return replies


# ---- bit for bit --------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["stability", "explore"])
def test_an_episode_through_the_api_equals_the_in_process_loop_and_the_episode_command(capsys, server, client,
                                                                                        method):
    attempts = 3
    replies = drive(client, new_body(method, attempts, id=f"bit-{method}"))
    grasps = [r["next"]["top_grasp"] for r in replies if r["next"] is not None]
    r = run_episode(OBJ, TRUTH, EpisodeSettings(method=method, attempts=attempts), RunContext(), seed=SEED,
                    estimate=EST, keep_planner=True)
    d = r.to_dict()
    assert grasps == [a["action"] for a in d["attempts"]]                     # exact floats
    assert replies[-1]["status"] == ("success" if d["success"] else "failed")
    shown = client.episode(f"bit-{method}")
    b = r.planner.belief
    from bayesgrasp.loop.outside_loop import particles_digest
    assert shown["belief"]["particles_sha256"] == particles_digest(b.particles, b.weights)
    # one format: the episode command reads the server's directory and tells the same
    by_cli = cli_json(capsys, "episode", "show", server.episodes / f"bit-{method}", "--json")
    assert by_cli["steps"] == shown["steps"] and by_cli["belief"] == shown["belief"]


def test_the_first_grasp_equals_the_episode_command_s_and_the_one_shot_plan_s(capsys, tmp_path, client):
    body = new_body("stability", 2)
    by_cli = cli_json(capsys, "episode", "new", "--object", OBJ, "--estimate", ",".join(map(repr, EST)), "--method",
                      "stability", "--attempts", "2", "--seed", SEED, "--dir", tmp_path / "ep", "--json")
    by_api = client.new_episode(**body)
    one_shot = client.plan(object=OBJ, estimate=EST, method="stability", seed=SEED)
    assert by_api["next"] == by_cli["next"] == one_shot["next"]
    assert by_api["status"] == "open" and by_api["attempts_made"] == 0
    from bayesgrasp.io.grasp_schema import validate
    validate(by_api["next"]["grasp"])                          # the grasp schema's shape


def test_a_one_shot_category_plan_equals_the_category_command_s(capsys, server, client):
    """POST /v1/plan with category and task answers what `bayesgrasp category --json` prints (the
    README's example: its task grasps ship in the package's cache); a bad category, task or method
    is refused with a JSON error and its code."""
    by_cli = cli_json(capsys, "category", "--category", "mug", "--task", "handle", "--scene-object", "mug/3",
                      "--object-pose", "0.02,-0.01,2.0", "--json")
    by_api = client.plan(category="mug", task="handle", object="mug/3", object_pose=[0.02, -0.01, 2.0])
    assert by_cli["grasp"] is not None and by_api["grasp"] == by_cli["grasp"]           # exact floats
    assert by_api == by_cli
    for body, needle in [(dict(category="teapot", task="handle", object="mug/3"), "category: no tasks for 'teapot'"),
                         (dict(category="mug", task="spout", object="mug/3"), "task: 'mug' has no task 'spout'"),
                         (dict(category="mug", task="handle", object="mug/3", method="fusion"), "an episode"),
                         (dict(category="mug", object="mug/3"), "category, task: give both")]:
        r = httpx.post(server.url + "/v1/plan", headers=AUTH, json=body, timeout=60)
        assert r.status_code == 422 and r.json()["error"]["code"] == "invalid_body", r.text
        assert needle in r.json()["error"]["message"], r.text


def test_an_episode_on_an_arm_through_the_api_equals_the_episode_command_s(capsys, tmp_path, server, client):
    """robot, robot_base: the arm as `episode new --robot --robot-base` takes it; the first grasp (its
    arm record included) is the command's; a bad arm option is refused and writes nothing."""
    by_cli = cli_json(capsys, "episode", "new", "--object", OBJ, "--estimate", ",".join(map(repr, EST)), "--method",
                      "stability", "--attempts", "2", "--seed", SEED, "--robot", "kuka_lbr4", "--robot-base",
                      "-0.55,0.05,0,0.1", "--dir", tmp_path / "ep", "--json")
    by_api = client.new_episode(**new_body("stability", 2, id="onarm", robot="kuka_lbr4",
                                           robot_base=[-0.55, 0.05, 0.0, 0.1]))
    assert by_api["next"] == by_cli["next"] and by_api["next"]["grasp"]["arm"]["reachable"] is True
    for body, needle in [(new_body("stability", 2, id="arm1", robot="no_arm"), "not a built-in arm"),
                         (new_body("stability", 2, id="arm2", flange="lbr4_link7"), "flange: only with robot"),
                         (new_body("stability", 2, id="arm3", robot="kuka_lbr4", flange="nope"), "no link 'nope'"),
                         (new_body("stability", 2, id="arm4", robot="kuka_lbr4", robot_base=[0, 0, 0]), "robot_base")]:
        with pytest.raises(ServiceError) as e:
            client.new_episode(**body)
        assert e.value.status in (400, 422) and needle in e.value.message, e.value
        assert not (server.episodes / body["id"]).exists()


def test_the_api_is_described_by_openapi_behind_the_token(server):
    doc = httpx.get(server.url + "/openapi.json", headers=AUTH, timeout=30).json()
    assert {"/v1/episodes", "/v1/episodes/{eid}/observations", "/v1/episodes/{eid}", "/v1/plan",
            "/v1/health"} <= set(doc["paths"])
    assert set(doc["components"]["schemas"]["Observation"]["required"]) == {"joints", "lifted", "request_id"}
    assert httpx.get(server.url + "/openapi.json", timeout=30).status_code == 401


# ---- refusals -----------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def open_episode_id(client):
    return client.new_episode(**new_body("stability", 3, id="refusals"))["id"]


GOOD = {"joints": [0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], "lifted": False}
AUTH = {"Authorization": f"Bearer {TOKEN}", "Content-Type": "application/json"}


@pytest.mark.parametrize("case, status, code", [
    ("no token", 401, "unauthorized"),
    ("wrong token", 401, "unauthorized"),
    ("token of another scheme", 401, "unauthorized"),
    ("path-like id ..", 400, "invalid_id"),
    ("path-like id with a dot", 400, "invalid_id"),
    ("path-like request id", 400, "invalid_id"),
    ("oversized body", 413, "body_too_large"),
    ("malformed JSON", 400, "malformed_json"),
    ("unknown field", 422, "invalid_body"),
    ("joints in degrees", 422, "refused"),
    ("no such episode", 404, "no_such_episode"),
])
def test_each_refusal_is_a_json_error_with_its_code_and_changes_nothing(server, open_episode_id, case, status, code):
    eid = open_episode_id
    state = server.episodes / eid / "episode.json"
    before = (state.read_bytes(), (server.episodes / eid / "requests.json").read_bytes())
    url, headers, content = f"/v1/episodes/{eid}/observations", dict(AUTH), json.dumps({**GOOD, "request_id": "r"})
    if case == "no token":
        del headers["Authorization"]
    elif case == "wrong token":
        headers["Authorization"] = "Bearer " + TOKEN[:-1] + "x"
    elif case == "token of another scheme":
        headers["Authorization"] = "Basic " + TOKEN
    elif case == "path-like id ..":
        url = "/v1/episodes/%2E%2E/observations"
    elif case == "path-like id with a dot":
        url = f"/v1/episodes/{eid}.bak/observations"
    elif case == "path-like request id":
        content = json.dumps({**GOOD, "request_id": "../r"})
    elif case == "oversized body":
        content = json.dumps({**GOOD, "request_id": "r", "pad": "x" * (2 << 20)})
    elif case == "malformed JSON":
        content = content[:-5]
    elif case == "unknown field":
        content = json.dumps({**GOOD, "request_id": "r", "joint": [0]})
    elif case == "joints in degrees":
        content = json.dumps({**GOOD, "joints": [0, 80, 40, 80, 40, 80, 40], "request_id": "r"})
    elif case == "no such episode":
        url = "/v1/episodes/nowhere/observations"
    r = httpx.post(server.url + url, headers=headers, content=content, timeout=60)
    assert r.status_code == status, r.text
    err = r.json()["error"]
    assert err["code"] == code and err["message"] and "\n" not in err["message"], err
    assert (state.read_bytes(), (server.episodes / eid / "requests.json").read_bytes()) == before
    if status == 401:
        assert r.headers["www-authenticate"] == "Bearer"


def test_a_bad_episode_start_is_refused_and_leaves_no_directory(server, client):
    for body, needle in [(new_body("stability", 2, id="bad1", object="../../etc/passwd"), "object"),
                         (new_body("stability", 2, id="bad2", object="no_such_thing"), "not a built-in object"),
                         (new_body("grip", 2, id="bad3"), "method"),
                         (new_body("stability", 2, id="bad5", hand="token"), "not a built-in hand"),
                         (new_body("stability", 2, id="bad4", models={"n_sampels": 5}), "models.n_sampels")]:
        with pytest.raises(ServiceError) as e:
            client.new_episode(**body)
        assert e.value.status in (400, 422) and needle in e.value.message, e.value
        assert not (server.episodes / body["id"]).exists()


# ---- idempotence --------------------------------------------------------------------------------
def test_a_retried_observation_gets_the_same_reply_and_is_applied_once(server, client):
    eid = client.new_episode(**new_body("stability", 3, id="retry"))["id"]
    first = client.observe(eid, GOOD["joints"], False, request_id="obs-1")
    again = client.observe(eid, GOOD["joints"], False, request_id="obs-1")
    assert again == first and first["attempts_made"] == 1
    assert len(client.episode(eid)["steps"]) == 1
    with pytest.raises(ServiceError) as e:                    # the same id for another observation
        client.observe(eid, GOOD["joints"], True, request_id="obs-1")
    assert e.value.status == 409 and e.value.code == "request_id_reused"
    # a retried creation with the same id and body is the same episode; another body is refused
    assert client.new_episode(**new_body("stability", 3, id="retry"))["next"]["attempt"] == 1
    with pytest.raises(ServiceError) as e:
        client.new_episode(**new_body("explore", 3, id="retry"))
    assert e.value.status == 409 and e.value.code == "episode_exists"


def test_the_token_is_made_once_with_owner_only_permissions(tmp_path):
    token, created = load_or_create_token(tmp_path / "t" / "token")
    assert created and len(token) >= 32
    assert stat.S_IMODE(os.stat(tmp_path / "t" / "token").st_mode) == 0o600
    assert load_or_create_token(tmp_path / "t" / "token") == (token, False)


# ---- episodes at once, and the episode command beside the service -----------------------------
def test_concurrent_episodes_each_get_the_grasps_of_a_lone_one(client):
    """Six episodes observed from six threads at once, and two observations of one episode sent
    together: every episode ends as the same episode driven alone, each reading applied once."""
    readings = [GOOD["joints"], [0.7854, 1.4316, 1.2102, 1.3176, 1.1722, 1.4873, 1.2288]]
    alone = client.new_episode(**new_body("stability", 4, id="alone"))
    for k, q in enumerate(readings):
        alone = client.observe("alone", q, False, request_id=f"alone-{k}")
    ids = [client.new_episode(**new_body("stability", 4, id=f"conc-{i}"))["id"] for i in range(6)]
    out = {}

    def run(eid):
        for k, q in enumerate(readings):
            out[eid] = client.observe(eid, q, False, request_id=f"{eid}-{k}")

    threads = [threading.Thread(target=run, args=(eid,)) for eid in ids]
    for t in threads:
        t.start()
    for t in threads:
        t.join(300)
    assert all(out[eid] == {**alone, "id": eid} for eid in ids)
    # one episode, two observations at once: the lock puts them one after the other, both applied once
    client.new_episode(**new_body("stability", 4, id="same"))
    replies = {}
    pair = [threading.Thread(target=lambda k=k: replies.update({k: client.observe("same", readings[k], False,
                                                                                  request_id=f"same-{k}")}))
            for k in range(2)]
    for t in pair:
        t.start()
    for t in pair:
        t.join(300)
    steps = client.episode("same")["steps"]
    assert len(steps) == 2 and sorted(r["attempts_made"] for r in replies.values()) == [1, 2]
    assert sorted(s["joints"] for s in steps) == sorted(readings)


def test_the_episode_command_and_the_service_continue_each_other_s_episode(capsys, server, client):
    """A step by `bayesgrasp episode observe` on the server's directory, the next through the API
    (the warm episode is reopened from disk): the same as two steps through the API."""
    second = [0.7854, 1.4316, 1.2102, 1.3176, 1.1722, 1.4873, 1.2288]
    client.new_episode(**new_body("stability", 4, id="api-only"))
    client.observe("api-only", GOOD["joints"], False, request_id="a1")
    ref = client.observe("api-only", second, False, request_id="a2")
    client.new_episode(**new_body("stability", 4, id="mixed"))
    cli_json(capsys, "episode", "observe", server.episodes / "mixed", "--joints", ",".join(map(str, GOOD["joints"])),
             "--lifted", "no", "--json")
    assert client.observe("mixed", second, False, request_id="m2") == {**ref, "id": "mixed"}
    assert client.episode("mixed")["belief"] == client.episode("api-only")["belief"]


# ---- TLS and the command's own refusals ---------------------------------------------------------
def test_with_a_certificate_and_key_it_serves_https_only(tmp_path):
    cert, key = tmp_path / "cert.pem", tmp_path / "key.pem"
    subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", str(key), "-out",
                    str(cert), "-days", "1", "-subj", "/CN=127.0.0.1", "-addext", "subjectAltName=IP:127.0.0.1"],
                   check=True, capture_output=True)
    (tmp_path / "token").write_text(TOKEN)
    s = Server(tmp_path / "episodes", tmp_path / "token", extra=("--certfile", str(cert), "--keyfile", str(key)),
               verify=ssl.create_default_context(cafile=str(cert)))
    try:
        assert s.url.startswith("https://")
        assert Client(s.url, TOKEN, cafile=str(cert)).health()["status"] == "ok"
        with pytest.raises(httpx.TransportError):            # plain HTTP gets no answer
            httpx.get(f"http://127.0.0.1:{s.port}/v1/health", timeout=10)
        with pytest.raises(httpx.TransportError):            # nor does a client that does not trust the cert
            httpx.get(s.url + "/v1/health", timeout=10)
    finally:
        s.stop()


@pytest.mark.parametrize("argv, needle", [
    (["--certfile", "c.pem"], "--certfile, --keyfile: give both"),
    (["--certfile", "c.pem", "--keyfile", "k.pem"], "--certfile: no such file"),
    (["--token-file", "short"], "must hold one token of at least 16 characters"),
])
def test_the_command_refuses_bad_options_before_serving(capsys, tmp_path, monkeypatch, argv, needle):
    from bayesgrasp.cli import main

    monkeypatch.chdir(tmp_path)
    (tmp_path / "short").write_text("abc\n")
    assert main(["serve", "--episodes", "eps", "--port", str(free_port()), *argv]) == 2
    err = capsys.readouterr().err
    assert needle in err and len(err.strip().splitlines()) == 1, err


# ---- a SIGKILL in the middle of an observation --------------------------------------------------
def _requests(directory):
    try:
        return json.loads((directory / "requests.json").read_text())["requests"]
    except (OSError, ValueError, KeyError):
        return {}


def test_a_server_killed_mid_observation_and_restarted_loses_and_repeats_nothing(tmp_path, client):
    """The server is killed as soon as it has recorded the observation's request id (the planner's
    update and the next plan still to come); the client's retry after the restart, with the same
    request id, gets the reply an unkilled server gives, and the episode holds the step once."""
    episodes, token_file = tmp_path / "episodes", tmp_path / "token"
    s = Server(episodes, token_file)                        # no token file: the server makes one
    try:
        token = token_file.read_text().strip()
        assert token in s.output()                          # and prints it
        c = Client(s.url, token, retries=0)
        eid = c.new_episode(**new_body("explore", 4, id="killed"))["id"]
        reference = client.new_episode(**new_body("explore", 4, id="unkilled"))
        expected = client.observe(reference["id"], GOOD["joints"], False, request_id="kill-1")

        killed_mid = False
        result = {}
        t = threading.Thread(target=lambda: result.update(
            reply=_try(lambda: c.observe(eid, GOOD["joints"], False, request_id="kill-1"))))
        t.start()
        deadline = time.time() + 60
        while "kill-1" not in _requests(episodes / eid) and time.time() < deadline:
            time.sleep(0.0005)
        s.kill()
        killed_mid = _requests(episodes / eid).get("kill-1", {}).get("reply", "absent") is None
        t.join(60)
        assert isinstance(result["reply"], Exception)       # the client got no reply: it retries
        s.stop()
        # the client retries while the server restarts (its start takes seconds), the same request id
        restarted = {}
        starter = threading.Thread(target=lambda: restarted.update(s=Server(episodes, token_file, port=s.port)))
        starter.start()
        c = Client(s.url, token, retries=400, backoff=0.1, max_backoff=0.5)
        reply = c.observe(eid, GOOD["joints"], False, request_id="kill-1")
        starter.join(START_SECONDS)
        s = restarted["s"]
        assert reply == {**expected, "id": eid}
        assert c.observe(eid, GOOD["joints"], False, request_id="kill-1") == reply
        steps = c.episode(eid)["steps"]
        assert len(steps) == 1 and steps[0]["joints"] == GOOD["joints"]
        assert killed_mid, "the kill landed after the reply was recorded: the test did not hit the window"
    finally:
        s.stop()


def _try(f):
    try:
        return f()
    except Exception as e:   # the connection dies with the server
        return e


# ---- the README's exchange ----------------------------------------------------------------------
def readme_exchange() -> str:
    text = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    start = text.index("```bash\n.venv/bin/bayesgrasp serve") + len("```bash\n")
    return text[start:text.index("```", start)]


def test_the_readme_s_curl_exchange_runs_as_written(tmp_path):
    """The README's block in a fresh directory (our interpreter for .venv/bin/bayesgrasp, a free
    port for 8765): the grasps are the README transcript's, the call without a token is refused."""
    port = free_port()
    script = readme_exchange().replace(".venv/bin/bayesgrasp", f"{sys.executable} -m bayesgrasp.cli") \
        .replace("8765", str(port))
    assert f"--port {port}" in script
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(   # absolute: the block runs elsewhere
        str(Path(p).resolve()) for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p))
    p = subprocess.Popen(["bash", "-c", script], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, env=env, start_new_session=True)
    try:
        out, err = p.communicate(timeout=180)
    finally:
        try:
            os.killpg(p.pid, signal.SIGKILL)      # the block's server too, if it is still there
        except ProcessLookupError:
            pass
    assert p.returncode == 0, err
    new, observed, shown, health = [json.loads(line) for line in out.splitlines()]
    assert new["id"] == "ep1" and new["status"] == "open"
    np.testing.assert_allclose(new["next"]["top_grasp"], [0.0386, -0.0389, -2.3817], atol=5e-5)   # the README's
    np.testing.assert_allclose(observed["next"]["top_grasp"], [0.0393, -0.0242, -0.6219], atol=5e-5)
    assert observed["attempts_made"] == 1 and len(shown["steps"]) == 1 and shown["status"] == "open"
    assert health["error"]["code"] == "unauthorized"
    assert (tmp_path / "episodes" / "ep1" / "episode.json").is_file()
