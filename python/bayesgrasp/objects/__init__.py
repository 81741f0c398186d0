"""Objects and scenes: mesh loading, the built-in procedural library, table-top scenes.

>>> from bayesgrasp.objects import load_object, Scene
>>> mug = load_object("mug")            # built-in (see list_objects()) or a path to OBJ/STL/PLY
>>> scene = Scene()
>>> i = scene.add_object(mug, x=0.1, y=0.0, yaw=0.3)
>>> V, F = scene.object_mesh_world(i)   # (N, 3) float64, (M, 3) int32 in the world frame
"""
from .library import (CATEGORY_SIZES, NewMemberWarning, builtin, categories, category, generate, list_objects, load_object,
                      object_params, sample_params)
from .primitives import boolean_available
from .mesh_io import DEFAULT_DENSITY, MESH_EXTENSIONS, MeshWarning, ObjectModel, load_mesh, mesh_from_object
from .topology import mesh_is_watertight
from .scene import Scene, TableScene

__all__ = [
    "CATEGORY_SIZES", "DEFAULT_DENSITY", "MESH_EXTENSIONS", "MeshWarning", "NewMemberWarning", "ObjectModel", "Scene",
    "TableScene", "boolean_available", "builtin", "categories", "category", "generate",
    "list_objects", "load_mesh", "load_object", "mesh_from_object", "mesh_is_watertight", "object_params",
    "sample_params",
]
