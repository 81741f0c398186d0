"""``bayesgrasp serve``: the robot loop as an HTTP JSON service (FastAPI on uvicorn).

A robot's stack calls it instead of running ``bayesgrasp episode`` once per step: episodes are kept
warm in memory (the planner is not rebuilt per observation) and on disk in the format the episode
command writes, so either can continue an episode the other started. It sits beside the CLI and
calls the loop layer (:mod:`bayesgrasp.loop`) and nothing else.

:mod:`.settings` (the service's options, checked in one place), :mod:`.security` (the bearer
token, the body size limit, the episode id pattern), :mod:`.errors` (every refusal as one JSON
shape), :mod:`.bodies` (the request bodies), :mod:`.store` (the warm episodes and their locks),
:mod:`.routes` (the endpoints) and :mod:`.app` (the application and the server)."""
