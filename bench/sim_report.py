"""Summarises the contact-simulation benchmarks (bench/run_sim.sh): medians over repetitions,
our auto-grasp vs GraspIt!-style stepping vs pybullet, into bench/results/sim.json."""
from __future__ import annotations

import argparse
import json
from pathlib import Path


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--results", default="bench/results")
    res = Path(ap.parse_args().results)
    gb = json.loads((res / "bench_sim.json").read_text())
    med = {}
    for b in gb["benchmarks"]:
        if b.get("aggregate_name") == "median" or b.get("run_type") == "iteration" and b["run_name"] not in med:
            med[b["run_name"]] = b
    def rate(name):
        b = med[name]
        return b["grasps_per_s"], b.get("queries_per_grasp"), b.get("steps_per_grasp"), b.get("label", "")
    agree = json.loads((res / "sim_agreement.json").read_text())
    peer = json.loads((res / "sim_pybullet.json").read_text())
    top, top_q, top_s, _ = rate("BM_TopGrasp/0")
    close, close_q, close_s, _ = rate("BM_Close")
    fixed, fixed_q, fixed_s, _ = rate("BM_CloseFixedStep")
    variants = {rate(f"BM_TopGrasp/{v}")[3]: rate(f"BM_TopGrasp/{v}")[0] for v in range(6) if f"BM_TopGrasp/{v}" in med}
    batch = {k.split(":")[-1].split("/")[0]: med[k]["grasps_per_s"] for k in med if k.startswith("BM_TopGraspBatch")}
    out = {
        "mug": agree["mug"], "triangles": agree["triangles"], "grasps": agree["grasps"],
        "top_grasp_per_cpu_s": top, "top_grasp_ms": 1e3 / top, "top_grasp_queries": top_q, "top_grasp_steps": top_s,
        "close_per_cpu_s": close, "close_ms": 1e3 / close, "close_queries": close_q, "close_steps": close_s,
        "graspit_fixed_step_per_cpu_s": fixed, "graspit_fixed_step_queries": fixed_q, "graspit_fixed_step_steps": fixed_s,
        "ratio_close_vs_graspit_style": close / fixed,
        "joint_agreement_vs_graspit_style_deg": agree["finger_joint_diff_deg"],
        "pybullet_per_s": peer["grasps_per_s"], "ratio_close_vs_pybullet": close / peer["grasps_per_s"],
        "ratio_top_grasp_vs_pybullet": top / peer["grasps_per_s"],
        "pybullet": peer, "representation_variants_top_grasp_per_cpu_s": variants,
        "top_grasp_batch_wall_per_s_by_threads": batch,
        "target_top_grasp_per_s": 2000,
    }
    (res / "sim.json").write_text(json.dumps(out, indent=2) + "\n")
    print(f"mug {agree['triangles']} triangles, {agree['grasps']} random top grasps, one core (per CPU second)")
    print(f"  top grasp (descent + close): {top:8.0f}/s  ({1e3 / top:.3f} ms, {top_q:.1f} FCL queries, {top_s:.1f} steps)")
    print(f"  close alone:                 {close:8.0f}/s  ({1e3 / close:.3f} ms, {close_q:.1f} queries, {close_s:.1f} steps)")
    print(f"  GraspIt!-style 0.01 rad:     {fixed:8.0f}/s  ({fixed_q:.1f} queries, {fixed_s:.1f} steps)"
          f"  -> ours x{close / fixed:.1f}")
    a = agree["finger_joint_diff_deg"]
    print(f"  joint agreement vs GraspIt!-style: median {a['median']:.3f} deg, p90 {a['p90']:.3f}, "
          f"{100 * a['fraction_below_0.5']:.1f}% within 0.5 deg")
    print(f"  pybullet POSITION_CONTROL:   {peer['grasps_per_s']:8.1f}/s (wall, median)  -> ours (close) "
          f"x{close / peer['grasps_per_s']:.0f}")
    for k, v in variants.items():
        print(f"    variant {k:32s} {v:8.0f}/s")
    for k, v in batch.items():
        print(f"    batch threads={k}: {v:8.0f}/s (wall)")


if __name__ == "__main__":
    main()
