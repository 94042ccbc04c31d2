"""FeatureMesh benchmark (pvpython): full pipeline vs the classical voxel cut on every case.

usage: pvpython scripts/benchmark.py [--runs 3] [--cases a,b] [--out out/benchmark]
Cases: the bundled Data/ ones and every case in ../shared/data/cases (skipped with a message when
absent). Prints one table (median of --runs runs per stage; the voxel cut runs once per case when it
takes over 5 s) and writes it as Markdown and CSV.
"""
import argparse
import csv
import os
import platform
import statistics
import sys
import time

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403
import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import featuremesh as fm  # noqa: E402
from featuremesh import dice, seeds  # noqa: E402

ROOT = fm.ROOT


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cases", default="")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "benchmark"))
    args = ap.parse_args()
    fm.load_plugin(ns=globals())
    rows = []
    for name, d in fm.cases([c for c in args.cases.split(",") if c]).items():
        image = ps.OpenDataFile(os.path.join(d, "image.mha"))
        image.UpdatePipeline()
        scalars = image.PointData.keys()[0]
        so, sb = seeds(os.path.join(d, "seeds_object.csv")), seeds(os.path.join(d, "seeds_background.csv"))
        T = v2n(sm.Fetch(ps.OpenDataFile(os.path.join(d, "truth.mha"))).GetPointData().GetScalars())
        # Fresh proxies every run: re-executing a proxy would only measure ParaView's cache.
        times = {"nodes": [], "mesh": [], "cut": []}
        for _ in range(args.runs):
            nodes = FeatureNodes(Input=image, Scalars=["POINTS", scalars])
            mesh = DelaunayImageMesh(Nodes=nodes, Image=image, Scalars=["POINTS", scalars])
            cut = SuperVoxelCut(Mesh=mesh, ObjectSeeds=so, BackgroundSeeds=sb, Image=image, Scalars=["POINTS", scalars])
            so.UpdatePipeline()
            sb.UpdatePipeline()
            for key, proxy in (("nodes", nodes), ("mesh", mesh), ("cut", cut)):
                t = time.perf_counter()
                proxy.UpdatePipeline()
                times[key].append(time.perf_counter() - t)
        labelled = sm.Fetch(cut, idx=0)
        L = v2n(sm.Fetch(cut, idx=2).GetPointData().GetScalars())
        vt = []
        for _ in range(args.runs):
            vc = VoxelCut(Input=image, ObjectSeeds=so, BackgroundSeeds=sb, Scalars=["POINTS", scalars])
            t = time.perf_counter()
            vc.UpdatePipeline()
            vt.append(time.perf_counter() - t)
            if vt[-1] > 5:
                break
        V = v2n(sm.Fetch(vc).GetPointData().GetScalars())
        med = {k: statistics.median(v) for k, v in times.items()}
        total = sum(med.values())
        q = v2n(labelled.GetCellData().GetArray("MinAngle") or labelled.GetCellData().GetArray("MinDihedralAngle"))
        row = {"case": name, "voxels": T.size, "nodes": labelled.GetNumberOfPoints(), "elements": labelled.GetNumberOfCells(),
               "nodes_s": med["nodes"], "mesh_s": med["mesh"], "cut_s": med["cut"], "total_s": total,
               "voxel_cut_s": statistics.median(vt), "speedup": statistics.median(vt) / total,
               "dice_supervoxel": dice(L, T), "dice_voxel": dice(V, T), "min_quality_deg": float(q.min())}
        rows.append(row)
        print(" | ".join("%s %s" % (k, ("%.3f" % v) if isinstance(v, float) else v) for k, v in row.items()), flush=True)
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    keys = list(rows[0].keys()) if rows else []
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(rows)
    machine = "%s, %d cores, %s" % (platform.machine(), os.cpu_count(), platform.platform())
    lines = ["Machine: %s; medians of %d runs (voxel cut: once when over 5 s)." % (machine, args.runs), "",
             "| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(("%.3f" % r[k]) if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
