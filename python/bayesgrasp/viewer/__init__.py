"""The 3D view of a result in the browser (viser): :func:`scene_from_result` reads any command's
JSON into a :class:`ResultScene`; :func:`serve` shows it on a local viser server."""
from .scene import ResultError, ResultScene, Step, read_result, scene_from_result
from .serve import SceneView, serve

__all__ = ["ResultError", "ResultScene", "SceneView", "Step", "read_result", "scene_from_result", "serve"]
