"""Combines bench/results/gp_{cpp,peers,ours}.json into bench/results/gp.json and prints the
comparison table (medians; wall time and, beside it, process CPU time, which is the fairer
figure on a shared machine). Usage: python bench/gp_report.py bench/results"""
import json
import os
import sys

N, M, NS = 5000, 200, 100_000


def load(path):
    with open(path) as f:
        return json.load(f)


def cpp_figures(path):
    out = {}
    for b in load(path)["benchmarks"]:
        if b.get("aggregate_name") not in (None, "median"):
            continue
        name = b["run_name"] if "run_name" in b else b["name"]
        name = name.split("/min_time")[0].split("/iterations")[0].split("/repeats")[0]
        scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
        rec = {"wall_s": b["real_time"] * scale, "cpu_s": b["cpu_time"] * scale}
        for k, v in b.items():
            if k in ("GFLOPs", "pairs_per_s", "inputs_per_s", "lml", "evaluations"):
                rec[k] = v
        out[name] = rec
    return out


def main(rdir):
    cpp = cpp_figures(os.path.join(rdir, "gp_cpp.json"))
    peers = load(os.path.join(rdir, "gp_peers.json"))
    ours = load(os.path.join(rdir, "gp_ours.json"))
    pc, oc = peers.get("cpu_s", {}), ours.get("cpu_s", {})
    # FLOP bounds at the faster one-thread GEMM rate of the two we link (Eigen, OpenBLAS)
    gflops = max(cpp["BM_dgemm_eigen"]["GFLOPs"], cpp.get("BM_dgemm_blas", {}).get("GFLOPs", 0.0)) / 1e9
    rows, report = [], {"cpp": cpp, "peers": peers, "ours": ours, "derived": {}}
    der = report["derived"]
    der["eigen_dgemm_gflops"] = cpp["BM_dgemm_eigen"]["GFLOPs"] / 1e9
    der["blas_dgemm_gflops"] = cpp.get("BM_dgemm_blas", {}).get("GFLOPs", float("nan")) / 1e9
    der["bound_dgemm_gflops"] = gflops

    def row(what, o_wall, o_cpu, p_wall, p_cpu, peer):
        r = {"what": what, "ours_wall_s": o_wall, "ours_cpu_s": o_cpu, "peer": peer, "peer_wall_s": p_wall,
             "peer_cpu_s": p_cpu}
        if p_wall and o_wall:
            r["speedup_wall"] = p_wall / o_wall
        if p_cpu and o_cpu:
            r["speedup_cpu"] = p_cpu / o_cpu
        rows.append(r)

    if "gpy_error" not in peers:
        row("FITC train to convergence", ours["ours_fitc_train_s"], oc.get("ours_fitc_train_s"),
            peers["gpy_fitc_train_s"], pc.get("gpy_fitc_train_s"), "GPy FITC")
        row("FITC objective+gradient (C++)", cpp["BM_fitc_objective"]["wall_s"], cpp["BM_fitc_objective"]["cpu_s"],
            peers["gpy_fitc_objective_s"], pc.get("gpy_fitc_objective_s"), "GPy FITC")
        row("FITC objective+gradient (Python)", ours["ours_fitc_objective_s"], oc.get("ours_fitc_objective_s"),
            peers["gpy_fitc_objective_s"], pc.get("gpy_fitc_objective_s"), "GPy FITC")
        row("predict mean, 100k (C++)", cpp["BM_fitc_predict_mean_100k"]["wall_s"],
            cpp["BM_fitc_predict_mean_100k"]["cpu_s"], peers["gpy_predict_mean_100k_s"],
            pc.get("gpy_predict_mean_100k_s"), "GPy FITC")
        row("predict mean, 100k (Python)", ours["ours_predict_mean_100k_s"], oc.get("ours_predict_mean_100k_s"),
            peers["gpy_predict_mean_100k_s"], pc.get("gpy_predict_mean_100k_s"), "GPy FITC")
        row("predict mean+var, 100k (C++)", cpp["BM_fitc_predict_mean_var_100k"]["wall_s"],
            cpp["BM_fitc_predict_mean_var_100k"]["cpu_s"], peers["gpy_predict_mean_var_100k_s"],
            pc.get("gpy_predict_mean_var_100k_s"), "GPy FITC")
        row("predict mean+std, 100k (Python)", ours["ours_predict_mean_var_100k_s"],
            oc.get("ours_predict_mean_var_100k_s"), peers["gpy_predict_mean_var_100k_s"],
            pc.get("gpy_predict_mean_var_100k_s"), "GPy FITC")
        der["lml_ours"] = ours["ours_fitc_lml"]
        der["lml_gpy"] = peers["gpy_fitc_lml"]
        der["lml_rel_diff"] = abs(ours["ours_fitc_lml"] - peers["gpy_fitc_lml"]) / abs(peers["gpy_fitc_lml"])
        der["evaluations_ours"] = ours["ours_fitc_evaluations"]
        der["evaluations_gpy"] = peers["gpy_fitc_evaluations"]
    if "sklearn_error" not in peers:
        row("exact GP fit, N=2000 (fixed hyper-parameters)", ours["ours_exact_fit_s"], oc.get("ours_exact_fit_s"),
            peers["sklearn_exact_fit_s"], pc.get("sklearn_exact_fit_s"), "scikit-learn")
        row("exact GP predict mean, 10k", ours["ours_exact_predict_mean_10k_s"],
            oc.get("ours_exact_predict_mean_10k_s"), peers["sklearn_exact_predict_mean_10k_s"],
            pc.get("sklearn_exact_predict_mean_10k_s"), "scikit-learn")
        row("exact GP predict mean+std, 10k", ours["ours_exact_predict_mean_std_10k_s"],
            oc.get("ours_exact_predict_mean_std_10k_s"), peers["sklearn_exact_predict_mean_std_10k_s"],
            pc.get("sklearn_exact_predict_mean_std_10k_s"), "scikit-learn")
    # FLOP bounds at the measured one-thread dgemm rate
    obj = cpp["BM_fitc_objective"]
    t_bound = 3.0 * N * M * M / (gflops * 1e9)
    der["objective_bound_3NM2_s"] = t_bound
    der["objective_time_over_bound_cpu"] = obj["cpu_s"] / t_bound
    der["objective_time_over_bound_wall"] = obj["wall_s"] / t_bound
    mv = cpp["BM_fitc_predict_mean_var_100k"]
    v_bound = 2.0 * M * M * NS / (gflops * 1e9)
    der["mean_var_bound_2M2_s"] = v_bound
    der["mean_var_time_over_bound_cpu"] = mv["cpu_s"] / v_bound
    der["mean_var_time_over_bound_wall"] = mv["wall_s"] / v_bound
    for k in ("BM_hot_loop_pairs/20", "BM_hot_loop_pairs/200"):
        if k in cpp:  # K candidates x 500 particles per call
            der[k.replace("BM_", "") + "x500_pairs_per_s_cpu"] = (int(k.split("/")[1]) * 500) / cpp[k]["cpu_s"]
            der[k.replace("BM_", "") + "x500_pairs_per_s_wall"] = (int(k.split("/")[1]) * 500) / cpp[k]["wall_s"]
    report["rows"] = rows
    with open(os.path.join(rdir, "gp.json"), "w") as f:
        json.dump(report, f, indent=1)

    print(f"\n{'workload':48s} {'ours wall/cpu [ms]':>22s} {'peer wall/cpu [ms]':>22s} {'speed-up wall/cpu':>18s}  peer")
    for r in rows:
        f = lambda x: "-" if x is None else f"{1e3 * x:.1f}"
        g = lambda x: "-" if x is None else f"{x:.1f}x"
        print(f"{r['what']:48s} {f(r['ours_wall_s']) + ' / ' + f(r['ours_cpu_s']):>22s} "
              f"{f(r['peer_wall_s']) + ' / ' + f(r['peer_cpu_s']):>22s} "
              f"{g(r.get('speedup_wall')) + ' / ' + g(r.get('speedup_cpu')):>18s}  {r['peer']}")
    print()
    for k, v in der.items():
        print(f"  {k:42s} {v:.6g}" if isinstance(v, float) else f"  {k:42s} {v}")
    for k in ("gpy_error", "sklearn_error"):
        if k in peers:
            print(f"  {k}: {peers[k]}")
    for k in ("fitc_mean_max_abs_diff_vs_gpy", "fitc_std_max_abs_diff_vs_gpy", "exact_mean_max_abs_diff_vs_sklearn",
              "exact_var_max_abs_diff_vs_sklearn", "exact_lml_diff_vs_sklearn"):
        if k in ours:
            print(f"  {k:42s} {ours[k]:.3g}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "bench/results")
