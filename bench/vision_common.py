"""Shared by the registration benchmark scripts (numpy only: runs in both virtual environments)."""
import numpy as np


def load_views(path):
    with np.load(path) as z:
        d = {k: z[k] for k in z.files}  # each array read (and decompressed) once
    views = []
    for i in range(len(d["offsets"]) - 1):
        views.append(dict(points=d["points"][d["offsets"][i]:d["offsets"][i + 1]], eye=d["eye"][i],
                          T_true=d["T_true"][i], model=int(d["model"][i])))
    models = []
    mo = d["model_offsets"]
    for k in range(len(mo) - 1):
        models.append(dict(points=d["model_points"][mo[k]:mo[k + 1]], normals=d["model_normals"][mo[k]:mo[k + 1]],
                           name=str(d["model_names"][k]), axis=d["symmetry_axis"][k]))
    return views, models, float(d["voxel"])


def errors(T_est, T_true, axis):
    """(rotation error in degrees, symmetry-aware about `axis` (model frame) if non-zero;
    translation error in metres of the model origin... measured at the model's origin)."""
    Ra, Rb = T_est[:3, :3], T_true[:3, :3]
    if np.linalg.norm(axis) > 0:
        a = axis / np.linalg.norm(axis)
        c = np.clip((Ra @ a) @ (Rb @ a), -1, 1)
    else:
        c = np.clip((np.trace(Ra.T @ Rb) - 1) / 2, -1, 1)
    return float(np.degrees(np.arccos(c))), float(np.linalg.norm(T_est[:3, 3] - T_true[:3, 3]))


def summarise(name, rows):
    ok = [r["success"] for r in rows]
    t = np.array([r["time"] for r in rows])
    out = {"method": name, "views": len(rows), "success_rate": float(np.mean(ok)),
           "median_time_s": float(np.median(t)), "mean_time_s": float(np.mean(t))}
    for k in ("time_features", "time_global", "time_icp"):
        if k in rows[0]:
            out["median_" + k] = float(np.median([r[k] for r in rows]))
    return out
