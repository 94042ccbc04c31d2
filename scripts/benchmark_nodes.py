"""Feature Nodes per-step benchmark (pvpython): median step times over repeated runs.

usage: pvpython scripts/benchmark_nodes.py [--runs 15] [--cases nuclei-dsb2018,brain-tumour-brats-0005]
Prints one table, milliseconds per step (the filter's StepSeconds field array) and the filter's
wall time, with the node count, for each case (bundled Data/ first, then ../shared/data/cases).
Issue 2 targets on a 2-core machine: 512x512 <= 15 ms, BraTS (240x240x155) <= 600 ms.
"""
import argparse
import os
import statistics
import time

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403
import paraview.simple as ps

import featuremesh as fm

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--cases", default="nuclei-dsb2018,brain-tumour-brats-0005")
    args = ap.parse_args()
    fm.load_plugin(ns=globals())
    rows, steps = [], []
    for name in args.cases.split(","):
        folder = fm.case_dir(name)
        path = folder and os.path.join(folder, "image.mha")
        if not path:
            print("note: case %s not found, skipped" % name)
            continue
        image = ps.OpenDataFile(path)
        image.UpdatePipeline()
        scalars = image.PointData.keys()[0]
        times, walls, count = {}, [], 0
        for _ in range(args.runs):
            # A fresh proxy every run: re-executing one would only measure ParaView's cache.
            nodes = FeatureNodes(Input=image, Scalars=["POINTS", scalars])
            t0 = time.perf_counter()
            nodes.UpdatePipeline()
            walls.append(time.perf_counter() - t0)
            out = sm.Fetch(nodes)
            count = out.GetNumberOfPoints()
            field = out.GetFieldData().GetArray(fm.names.StepSeconds)
            for c in range(field.GetNumberOfComponents()):
                key = field.GetComponentName(c)
                times.setdefault(key, []).append(field.GetComponent(0, c))
                if key not in steps:
                    steps.append(key)
            ps.Delete(nodes)
        dims = sm.Fetch(image).GetDimensions()
        rows.append((name, "x".join(str(d) for d in dims if d > 1), count,
                     {k: 1000 * statistics.median(v) for k, v in times.items()},
                     1000 * sum(statistics.median(v) for v in times.values()), 1000 * statistics.median(walls)))
    header = ["case", "dims", "nodes"] + steps + ["sum of steps", "filter wall"]
    print("Feature Nodes, median of %d runs, ms (%d cores)" % (args.runs, os.cpu_count()))
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for name, dims, count, t, total, wall in rows:
        cells = [name, dims, str(count)] + ["%.1f" % t.get(k, 0.0) for k in steps] + ["%.1f" % total, "%.1f" % wall]
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
