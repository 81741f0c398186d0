"""Driver for the peer planner cgn-pytorch 0.4.3 (Contact-GraspNet in PyTorch, Peralta, MIT).

Run by the python of its own virtual environment (`.venv-peer-cgn`, see README.md here):

    .venv-peer-cgn/bin/python bench/peers/cgn_driver.py REQUEST.json RESULT.json

Request (JSON): {"cloud": (N, 3) .npy partial view in the table frame (metres, z up),
                 "top_k": 5, "seed": 0; "mesh", "pose" and "hand" are accepted and only echoed}
Result (JSON):  {"planner", "version", "hand": "panda", "grasps": [{"pose", "score", "width",
                 "contact"}], "seconds", "counts", "patches"}. Contact-GraspNet has no lift test of
                 its own, so there is no "peer_lift_test".

What the peer does (read from its installed source): `inference()` keeps at most 20,000 points
(a random subset), takes 2,048 of them by farthest point sampling, runs a PointNet++ over the cloud
and predicts for each of the 2,048 points a grasp confidence (sigmoid of the first head), two
directions and a jaw width; the weights ship in the wheel (`checkpoints/current.pth`), nothing is
fetched. Its README asks for the cloud in the world frame with its mean subtracted (the scenes it
ships are so: z up, centred); this driver subtracts the mean and adds it back to the grasps.

Frame convention of the peer's grasp pose (`CGN.build_6d_grasps`), which is the Panda gripper
frame of Contact-GraspNet:
* +z is the approach direction (from the hand towards the object);
* +x is the closing direction ("baseline"): it points from the predicted contact point, on one
  finger, across to the other finger;
* +y = z cross x;
* the origin is the base of the gripper (the flange side of the Panda hand), gripper_depth =
  0.1034 m behind the fingertips: origin = contact - 0.1034 z + (width / 2) x, so the point midway
  between the fingertips is origin + 0.1034 z and the fingers sit at +/- width / 2 along x there.
`pose` in our result is this frame in the table frame (the mean added back); `contact` is the
predicted contact point; `width` is the predicted opening (m, clamped by the peer to at most
0.04 m with inference's gripper_width of 0.08, then ReLU).

Patches applied from here (the installed packages are never edited):
1. torch_geometric 2.4.0's `fps`, `radius` and `knn` call the compiled `torch_cluster` package
   (on PyPI only as a source archive to be compiled against torch; newer torch_geometric asks
   `pyg-lib`, which PyPI does not have). Pure-torch versions written here replace the names that
   cgn_pytorch and torch_geometric's `knn_interpolate` bound at import time.
   * fps: farthest point sampling, ceil(ratio * n) points per batch element, first point drawn
     from a seeded generator (torch_cluster draws it from the global one);
   * radius: for each query point the points within r in its batch element, at most
     max_num_neighbors, taken in index order (as torch_cluster's CUDA kernel and the original
     TensorFlow query_ball_point do);
   * knn: the k nearest points in the same batch element.
2. `CGN.forward` is wrapped to keep the predicted widths, which `inference()` does not return.
Python's `random` (the 20,000-point subset) and torch are seeded with the request's seed.
"""
import json
import math
import os
import random
import sys
import time

import numpy as np
import torch

PLANNER = "cgn-pytorch"
VERSION = "0.4.3"
GRIPPER_DEPTH = 0.1034   # inference()'s default, the Panda's base-to-fingertip distance
GRIPPER_WIDTH = 0.08

_generator = torch.Generator()


# ---- patch 1: pure-torch neighbourhood operations ----------------------------------------------
def _groups(batch, n, device):
    if batch is None:
        return torch.zeros(n, dtype=torch.long, device=device)
    return batch


def fps(x, batch=None, ratio=0.5, random_start=True, batch_size=None):
    """Farthest point sampling: indices into x, ceil(ratio * n_b) per batch element b."""
    batch = _groups(batch, x.size(0), x.device)
    out = []
    for b in torch.unique(batch, sorted=True):
        idx = torch.nonzero(batch == b).view(-1)
        pts = x[idx].double()
        m = min(int(math.ceil(float(ratio) * idx.numel())), idx.numel())
        first = int(torch.randint(idx.numel(), (1,), generator=_generator)) if random_start else 0
        chosen = torch.empty(m, dtype=torch.long)
        dist = torch.full((idx.numel(),), float("inf"), dtype=torch.float64)
        cur = first
        for i in range(m):
            chosen[i] = cur
            dist = torch.minimum(dist, ((pts - pts[cur]) ** 2).sum(dim=1))
            cur = int(torch.argmax(dist))
        out.append(idx[chosen.to(idx.device)])
    return torch.cat(out)


def _pair_blocks(x, y, batch_x, batch_y, block=512):
    """Squared distances from blocks of y to all of x, +inf across batch elements."""
    batch_x = _groups(batch_x, x.size(0), x.device)
    batch_y = _groups(batch_y, y.size(0), y.device)
    for s in range(0, y.size(0), block):
        yb = y[s:s + block]
        d2 = torch.cdist(yb.double(), x.double()) ** 2
        d2 = d2.masked_fill(batch_y[s:s + block, None] != batch_x[None, :], float("inf"))
        yield s, d2


def radius(x, y, r, batch_x=None, batch_y=None, max_num_neighbors=32, num_workers=1, batch_size=None):
    """[2, E] (row: index in y, col: index in x) of the x within r of each y, first ones by index."""
    rows, cols = [], []
    for s, d2 in _pair_blocks(x, y, batch_x, batch_y):
        within = d2 <= r * r
        keep = within & (torch.cumsum(within.int(), dim=1) <= max_num_neighbors)
        row, col = torch.nonzero(keep, as_tuple=True)
        rows.append(row + s)
        cols.append(col)
    return torch.stack([torch.cat(rows), torch.cat(cols)], dim=0)


def knn(x, y, k, batch_x=None, batch_y=None, cosine=False, num_workers=1, batch_size=None):
    """[2, E] (row: index in y, col: index in x) of the k nearest x of each y."""
    if cosine:
        raise NotImplementedError("knn: cosine distance is not needed by cgn_pytorch")
    rows, cols = [], []
    kk = min(int(k), x.size(0))
    for s, d2 in _pair_blocks(x, y, batch_x, batch_y):
        val, col = torch.topk(d2, kk, dim=1, largest=False)
        row = torch.arange(d2.size(0)).unsqueeze(1).expand_as(col)
        ok = torch.isfinite(val)
        rows.append(row[ok] + s)
        cols.append(col[ok])
    return torch.stack([torch.cat(rows), torch.cat(cols)], dim=0)


def install_patches():
    import torch_geometric.nn.pool as pool
    import cgn_pytorch  # noqa: F401  (its __init__ binds the name `inference` to the function)
    from cgn_pytorch.contact_graspnet import CGN
    pn2 = sys.modules["cgn_pytorch.pointnet2"]
    inf = sys.modules["cgn_pytorch.inference"]
    knn_interp = sys.modules["torch_geometric.nn.unpool.knn_interpolate"]
    pool.fps, pool.radius, pool.knn = fps, radius, knn
    pn2.fps, pn2.radius = fps, radius
    inf.farthest_point_sample = fps
    knn_interp.knn = knn

    # patch 2: keep the widths of the last forward pass
    original_forward = CGN.forward

    def forward(self, *args, **kwargs):
        out = original_forward(self, *args, **kwargs)
        self.bg_last_widths = out[3].detach().reshape(-1).cpu().numpy()
        self.bg_last_points = out[0].detach().reshape(-1, 3).cpu().numpy()
        return out

    CGN.forward = forward


def main(argv):
    if len(argv) != 3:
        sys.exit("usage: cgn_driver.py REQUEST.json RESULT.json")
    with open(argv[1]) as f:
        req = json.load(f)
    top_k = int(req.get("top_k", 5))
    seed = int(req.get("seed", 0))
    cloud = np.load(req["cloud"])
    if cloud.ndim != 2 or cloud.shape[1] != 3 or not np.all(np.isfinite(cloud)):
        raise ValueError(f"cloud: expected a finite (N, 3) array, got shape {cloud.shape}")
    torch.set_num_threads(int(req.get("threads", os.cpu_count() or 1)))

    start = time.perf_counter()
    random.seed(seed)
    torch.manual_seed(seed)
    _generator.manual_seed(seed)
    install_patches()
    import cgn_pytorch
    model, _, _ = cgn_pytorch.from_pretrained(device="cpu")
    mean = cloud.mean(axis=0)
    t_inf = time.perf_counter()
    with torch.no_grad():
        # threshold below 0 keeps every point's grasp, in the order of the captured widths
        grasps, conf, _ = cgn_pytorch.inference(model, (cloud - mean).astype(np.float32), threshold=-1.0,
                                                gripper_depth=GRIPPER_DEPTH, gripper_width=GRIPPER_WIDTH)
    t_inf = time.perf_counter() - t_inf
    widths = model.bg_last_widths
    contacts = model.bg_last_points
    order = np.argsort(-conf, kind="stable")[:top_k]
    out = []
    for i in order:
        pose = np.array(grasps[i], dtype=float)
        pose[:3, 3] += mean
        out.append({"pose": pose.tolist(), "score": float(conf[i]), "width": float(widths[i]),
                    "contact": (contacts[i] + mean).tolist()})
    seconds = time.perf_counter() - start

    result = {
        "planner": PLANNER, "version": VERSION, "hand": "panda",
        "frame": "table (z up, table top z = 0); pose = Panda base, +z approach, +x closing",
        "grasps": out, "seconds": seconds, "seconds_inference": t_inf,
        "counts": {"points_in": int(len(cloud)), "grasps": int(len(conf)),
                   "above_0.5": int(np.count_nonzero(conf > 0.5))},
        "seed": seed, "torch": torch.__version__, "threads": torch.get_num_threads(),
        "request": {k: req[k] for k in ("mesh", "pose", "hand") if k in req},
        "patches": ["torch_geometric fps/radius/knn -> pure torch (bench/peers/cgn_driver.py)",
                    "CGN.forward wrapped to keep the predicted widths"],
    }
    with open(argv[2], "w") as f:
        json.dump(result, f, indent=1)
    print(f"cgn-pytorch: {len(conf)} grasps, {result['counts']['above_0.5']} above 0.5, best "
          f"{float(conf[order[0]]):.3f}; {seconds:.1f} s ({t_inf:.1f} s inference)", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv)
