"""FeatureMesh benchmark (pvpython): full pipeline vs the classical voxel cut on every case.

usage: pvpython scripts/benchmark.py [--runs 3] [--cases a,b] [--out out/benchmark]
Cases: the bundled Data/ ones and every case in ../shared/data/cases (skipped with a message when
absent). Prints one table (median of --runs runs per stage; the voxel cut runs once per case when it
takes over 5 s) and writes it as Markdown and CSV.
"""
import argparse
import csv
import glob
import os
import platform
import statistics
import time

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403
import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def cases(selection):
    found = {}
    for root in (os.path.join(ROOT, "Data"), os.path.join(ROOT, "..", "shared", "data", "cases")):
        if not os.path.isdir(root):
            print("note: %s not found, its cases are skipped" % root)
            continue
        for d in sorted(glob.glob(os.path.join(root, "*", "image.mha"))):
            found.setdefault(os.path.basename(os.path.dirname(d)), os.path.dirname(d))
    return {k: v for k, v in found.items() if not selection or k in selection}


def seeds(path):
    return ps.TableToPoints(Input=ps.CSVReader(FileName=[path]), XColumn="x", YColumn="y", ZColumn="z")


def dice(a, b):
    a, b = a.astype(bool), b.astype(bool)
    return 2.0 * (a & b).sum() / max(1, a.sum() + b.sum())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cases", default="")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "benchmark"))
    args = ap.parse_args()
    plugin = glob.glob(os.path.join(ROOT, "build", "**", "FeatureMesh.so"), recursive=True)[0]
    LoadPlugin(plugin, ns=globals())
    rows = []
    for name, d in cases([c for c in args.cases.split(",") if c]).items():
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
