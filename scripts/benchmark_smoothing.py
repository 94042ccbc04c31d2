"""Stage 3 benchmark (pvpython): Image Mesh Smoothing against the unsmoothed mesh, side by side.

usage: pvpython scripts/benchmark_smoothing.py [--cases a,b] [--smoothing Method=0,FixedNodeSlack=0.5]
                                               [--runs 1] [--out out/benchmark_smoothing]
For every case with a truth (bundled Data/ and ../shared/data/cases), at the defaults of stages 1, 2
and 4: nodes and elements, added nodes, quality of the Delaunay mesh and of the smoothed one
(2D minimum / 1st-percentile / maximum angle; 3D the same of dihedral angles, element minima for
the percentile), super-voxel Dice of both, the oracle Dice of both (each element takes its
majority reference label), elements owning no voxel, and the smoothing filter's seconds (median of
--runs). Writes OUT.md and OUT.csv.
"""
import argparse
import os
import statistics
import time

import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

import featuremesh as fm
from featuremesh.report import write_table
from featuremesh import metrics


def quality(mesh):
    P = v2n(mesh.GetPoints().GetData())
    C = v2n(mesh.GetCells().GetConnectivityArray()).reshape(mesh.GetNumberOfCells(), -1)
    return metrics.mesh_quality(P, C)


def scores(case, mesh, truth, T):
    cut = case.super_voxel_cut(mesh, SuperVoxelIds=1)
    owner = v2n(fm.fetch(cut, 2).GetPointData().GetArray(fm.names.ElementId)).reshape(truth.shape)
    dice = fm.dice(fm.labels(cut), T)
    part = metrics.partition_scores(owner, truth)
    ps.Delete(cut)
    return dice, part["oracle_dice"]


def parse(text):
    out = {}
    for item in filter(None, text.split(",")):
        k, v = item.split("=")
        out[k] = float(v) if "." in v else int(v)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", default="")
    ap.add_argument("--smoothing", default="", help="Image Mesh Smoothing properties, e.g. Method=0,FixedNodeSlack=0.5")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark_smoothing"))
    args = ap.parse_args()
    props = parse(args.smoothing)
    fm.load_plugin()
    rows = []
    for name, d in fm.cases(args.cases).items():
        case = fm.Case(d)
        T = case.truth()
        if T is None:
            continue
        image = fm.fetch(case.image)
        truth = T.reshape(image.GetDimensions()[::-1]).astype(bool)
        nodes = case.feature_nodes()
        mesh = case.mesh(nodes)
        seconds = []
        for _ in range(args.runs):
            smoothed = case.smoothing(mesh, **props)
            t = time.perf_counter()
            smoothed.UpdatePipeline()
            seconds.append(time.perf_counter() - t)
        m0, m1 = fm.fetch(mesh), fm.fetch(smoothed)
        q0, q1 = quality(m0), quality(m1)
        d0, o0 = scores(case, mesh, truth, T)
        d1, o1 = scores(case, smoothed, truth, T)
        fd = m1.GetFieldData()
        row = {"case": name, "nodes": m0.GetNumberOfPoints(),
               "added_pct": 100.0 * fd.GetArray(fm.names.AddedNodes).GetValue(0) / m0.GetNumberOfPoints(),
               "elements_before": m0.GetNumberOfCells(), "elements_after": m1.GetNumberOfCells(),
               "min_before": q0["min"], "min_after": q1["min"], "p1_before": q0["p1"], "p1_after": q1["p1"],
               "max_before": q0["max"], "max_after": q1["max"],
               "dice_before": d0, "dice_after": d1, "oracle_before": o0, "oracle_after": o1,
               "empty_before_pct": 100.0 * (v2n(m0.GetCellData().GetArray(fm.names.PixelCount)) == 0).mean(),
               "empty_after_pct": 100.0 * (v2n(m1.GetCellData().GetArray(fm.names.PixelCount)) == 0).mean(),
               "smoothing_s": statistics.median(seconds),
               "sweeps_s": fd.GetArray(fm.names.SweepSeconds).GetValue(0),
               "refinement_s": fd.GetArray(fm.names.RefinementSeconds).GetValue(0),
               "slivers_s": fd.GetArray(fm.names.SliverSeconds).GetValue(0),
               "statistics_s": fd.GetArray(fm.names.StatisticsSeconds).GetValue(0)}
        rows.append(row)
        print(" | ".join("%s %s" % (k, ("%.3f" % v) if isinstance(v, float) else v) for k, v in row.items()), flush=True)
    keys = list(rows[0].keys()) if rows else []
    write_table(args.out, rows, keys, "Image Mesh Smoothing %s against the Delaunay mesh; angles in degrees (3D: dihedral)." % (
        args.smoothing or "at its defaults"))

if __name__ == "__main__":
    main()
