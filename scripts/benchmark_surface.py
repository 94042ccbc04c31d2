"""Stage 6 benchmark (pvpython): Segmentation Surface Smoothing against the cut's own boundary, side by side.

usage: pvpython scripts/benchmark_surface.py [--cases a,b] [--runs 3] [--out out/benchmark_surface]
For every 3D case with a truth (bundled Data/ and ../shared/data/cases), the main job's pipeline at
its defaults (Feature Nodes -> Delaunay Image Mesh -> Image Mesh Smoothing -> Super-Voxel Cut), then
the cut's boundary and Segmentation Surface Smoothing's at each method: Laplacian 3 (the thesis),
Taubin 3, Taubin 10 (the default) and Laplacian 1, each with the volume mesh (output 0 lies on the moved mesh) and
without it (the smoothed surface alone). Per row: the symmetric surface distance to the reference
object's boundary (the 0.5 iso-surface of the truth; area-weighted both ways, mean and 95 %
Hausdorff, world units; faces on the image box left out on both sides: the truth's iso-surface is
open there and the box faces are planar by design), the bending (metrics.bending: the mean angle
between adjacent faces' normals, whole surface), the object's volume change, the boundary nodes
short of their smoothed position and the share of the smoothing's displacement the mesh took, the
smallest dihedral angle of the mesh, and the filter's seconds (median of --runs; the core's surface
and volume-mesh seconds). Writes OUT.md and OUT.csv.
"""
import argparse
import csv
import os
import statistics

import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

import featuremesh as fm
from featuremesh import metrics

VARIANTS = [("Laplacian 3", dict(Method=0, Iterations=3)), ("Taubin 3", dict(Method=1, Iterations=3)),
            ("Taubin 10", dict(Method=1, Iterations=10)), ("Laplacian 1", dict(Method=0, Iterations=1))]


def field(data, name):
    a = data.GetFieldData().GetArray(name)
    return a.GetValue(0) if a is not None else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", default="")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark_surface"))
    args = ap.parse_args()
    fm.load_plugin()
    rows = []
    for name, folder in fm.cases(args.cases).items():
        case = fm.Case(folder)
        truth = case.truth()
        if truth is None or not case.is3d:
            continue
        nodes = case.feature_nodes()
        cut = case.super_voxel_cut(case.smoothing(case.mesh(nodes)))
        cut.UpdatePipeline()
        image = fm.fetch(case.image)
        reference = metrics.mask_surface(image, truth > 0)
        box = image.GetBounds()
        dice = fm.dice(fm.labels(cut), truth)

        def row(variant, surface, **extra):
            d = metrics.surface_distances(metrics.without_box_faces(surface, box), reference)
            r = {"case": name, "variant": variant, "dice": round(dice, 4), "faces": surface.GetNumberOfCells(),
                 "mean_distance": round(d["mean"], 3), "hd95": round(d["hd95"], 3), "bending": round(metrics.bending(surface), 1)}
            r.update(extra)
            rows.append(r)
            print(r, flush=True)

        row("cut boundary", fm.fetch(cut, 1))
        for label, props in VARIANTS:
            for volume in (1, 0):
                smooth = ps.SegmentationSurfaceSmoothing(LabelledMesh=ps.OutputPort(cut, 0), VolumeMesh=volume, **props)
                seconds, surface_s, volume_s = [], [], []
                for _ in range(args.runs):
                    smooth.MarkModified(smooth)
                    smooth.UpdatePipeline()
                    out = fm.fetch(smooth, 0)
                    seconds.append(field(out, "TotalSeconds"))
                    surface_s.append(field(out, "SurfaceSeconds"))
                    volume_s.append(field(out, "VolumeSeconds"))
                mesh = fm.fetch(smooth, 1)
                row(label + (" + volume mesh" if volume else " (surface only)"), out,
                    volume_change_pct=round(100 * field(out, "MeasureChange"), 2),
                    short_nodes="%d/%d" % (field(out, "ShortNodes"), field(out, "BoundaryNodes")),
                    reached=round(field(out, "ReachedFraction"), 3),
                    min_dihedral=round(float(v2n(mesh.GetCellData().GetArray(fm.names.MinDihedralAngle)).min()), 2),
                    seconds=round(statistics.median(seconds), 3), surface_seconds=round(statistics.median(surface_s), 4),
                    volume_seconds=round(statistics.median(volume_s), 3))
                ps.Delete(smooth)
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    keys = ["case", "variant", "dice", "faces", "mean_distance", "hd95", "bending", "volume_change_pct", "short_nodes", "reached", "min_dihedral",
            "seconds", "surface_seconds", "volume_seconds"]
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(rows)
    with open(args.out + ".md", "w") as f:
        f.write("| " + " | ".join(keys) + " |\n|" + "---|" * len(keys) + "\n")
        for r in rows:
            f.write("| " + " | ".join(str(r.get(k, "")) for k in keys) + " |\n")
    print("wrote", args.out + ".md")


if __name__ == "__main__":
    main()
