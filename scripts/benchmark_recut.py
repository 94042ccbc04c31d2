"""The kept re-cut (pvpython): what one seed edit costs once the mesh is made, as the GUI pays it.

usage: pvpython scripts/benchmark_recut.py [--edits 10] [--cases a,b] [--cut VoxelRefinement=0] [--out out/benchmark_recut]
Each case (the binary cases with their task from cases.csv, then the multi-label cases) runs
stages 1 -> 2 -> 3 and the Super-Voxel Cut once. Then the robot user's first seed (the most
interior voxel of the largest error region, with the truth's label, as benchmark_clicks.py and
benchmark_multilabel.py place it) is added and removed again, --edits times each, the last label
image held each time as a view holds it (the cut cannot rewrite it in place). One sample of a re-cut
is noisy on a shared VM; the medians of many are not. Per case and edit: the median and the smallest
of the cut's own seconds (its field data's CutTotalSeconds), and the medians of its parts:
SetupSeconds, GeodesicSeconds, FlowSeconds (one object) or ExpansionSeconds (labels), and
VoxelRefinementSeconds. --cut sets properties of the cut (as benchmark_multilabel.py's).
Without --cases: the binary object cases and the multi-label cases. Writes OUT.md and OUT.csv.
"""
import argparse
import csv
import os
import statistics
import tempfile

import numpy as np
import paraview.simple as ps

import featuremesh as fm
from featuremesh import report
from benchmark_multilabel import field, robot_seed, write_seeds

PARTS = ("CutTotalSeconds", "SetupSeconds", "GeodesicSeconds", "FlowSeconds", "ExpansionSeconds", "VoxelRefinementSeconds")


def delete_all():
    for p in ps.GetSources().values():
        ps.Delete(p)


def world(image, k, j, i):
    return image.GetPoint(image.ComputePointId([int(i), int(j), int(k)]))


def points(rows):
    return [float(c) for r in rows for c in r[:3]]


def edits(cut, apply, args):
    """{edit: {part: [seconds]}} over args.edits rounds of (add, remove), the label image held."""
    out = {"add": {p: [] for p in PARTS}, "remove": {p: [] for p in PARTS}}
    held = fm.labels(cut)
    for _ in range(args.edits):
        for kind in ("add", "remove"):
            apply(kind)
            cut.UpdatePipeline()
            held = fm.labels(cut)  # noqa: F841 (held like a view's image)
            for p in PARTS:
                out[kind][p].append(field(cut, p))
    return out


def binary_case(name, folder, args):
    case = fm.Case(folder)
    image = fm.fetch(case.image)
    shape = image.GetDimensions()[::-1]
    spacing = np.asarray(image.GetSpacing())
    truth = case.truth().astype(np.uint8)
    rows = {}
    for kind in ("object", "background"):
        pts = np.loadtxt(os.path.join(folder, "seeds_%s.csv" % kind), delimiter=",", skiprows=1, ndmin=2)
        rows[kind] = [tuple(p) for p in pts]
    object_source, background_source = ps.PolyPointSource(Points=points(rows["object"])), ps.PolyPointSource(
        Points=points(rows["background"]))
    mesh = case.smoothing(case.mesh(case.feature_nodes()))
    cut = ps.SuperVoxelCut(Mesh=mesh, ObjectSeeds=object_source, BackgroundSeeds=background_source, Image=case.image,
                           Scalars=case.scalars, **case.with_task(dict(args.cut)))
    cut.UpdatePipeline()
    found = robot_seed(fm.labels(cut), truth, shape, spacing)
    if found is None:
        delete_all()
        return None  # the cut is right: no seed to add
    k, j, i, label = found
    kind = "object" if label else "background"
    source = object_source if label else background_source
    added = rows[kind] + [world(image, k, j, i)]

    def apply(edit):
        source.Points = points(added if edit == "add" else rows[kind])

    times = edits(cut, apply, args)
    elements = fm.fetch(cut, 0).GetNumberOfCells()
    delete_all()
    return {"case": name, "labels": 2, "elements": elements, "seed": kind, "times": times}


def multilabel_case(name, folder, args, tmp):
    case = fm.MultiLabelCase(folder)
    image = fm.fetch(case.image)
    shape = image.GetDimensions()[::-1]
    spacing = np.asarray(image.GetSpacing())
    truth = case.truth()
    rows = list(case.seed_rows())
    mesh = case.mesh()
    cut = case.super_voxel_cut(mesh, **args.cut)
    cut.UpdatePipeline()
    found = robot_seed(fm.labels(cut), truth, shape, spacing)
    if found is None:
        delete_all()
        return None
    k, j, i, label = found
    readers = {}
    for edit, seeds in (("add", rows + [tuple(world(image, k, j, i)) + (label,)]), ("remove", rows)):
        path = os.path.join(tmp, "%s-%s.csv" % (name, edit))
        write_seeds(path, seeds)
        readers[edit] = ps.CSVReader(FileName=[path])
        readers[edit].UpdatePipeline()

    def apply(edit):
        cut.Seeds = readers[edit]

    times = edits(cut, apply, args)
    elements = fm.fetch(cut, 0).GetNumberOfCells()
    delete_all()
    return {"case": name, "labels": len(case.names), "elements": elements, "seed": case.names[label], "times": times}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--edits", type=int, default=10)
    ap.add_argument("--cases", default="")
    ap.add_argument("--cut", default="", type=fm.parse_properties, help="properties of the cut, e.g. VoxelRefinement=0")
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark_recut"))
    args = ap.parse_args()
    fm.load_plugin()
    selection = [c for c in args.cases.split(",") if c]
    binary = {n: f for n, f in fm.cases(selection).items() if selection or fm.case_task(n) == "object"}
    labelled = fm.multilabel_cases(selection)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, folder in binary.items():
            if os.path.exists(os.path.join(folder, "truth.mha")):
                results.append(binary_case(name, folder, args))
                print(name, "no seed to add" if results[-1] is None else "", flush=True)
        for name, folder in labelled.items():
            results.append(multilabel_case(name, folder, args, tmp))
            print(name, "no seed to add" if results[-1] is None else "", flush=True)
    results = [r for r in results if r is not None]
    lines = ["# The kept re-cut", "", report.machine(), "",
             "The robot's first seed added and removed %d times each, the label image held; seconds of the cut "
             "(median, smallest in brackets) and the medians of its parts." % args.edits, "",
             "| case | labels | elements | seed | edit | cut | setup | geodesic | flow / expansion | voxel refinement |",
             "|---" * 10 + "|"]
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "labels", "elements", "seed", "edit", "part", "median_s", "min_s"])
        for r in results:
            for edit, parts in r["times"].items():
                med = {p: statistics.median(v) for p, v in parts.items()}
                for p, v in parts.items():
                    w.writerow([r["case"], r["labels"], r["elements"], r["seed"], edit, p, "%.4f" % med[p], "%.4f" % min(v)])
                solve = med["FlowSeconds"] if r["labels"] == 2 else med["ExpansionSeconds"]
                lines.append("| %s | %d | %d | %s | %s | %.3f (%.3f) | %.3f | %.3f | %.3f | %.3f |" % (
                    r["case"], r["labels"], r["elements"], r["seed"], edit, med["CutTotalSeconds"],
                    min(parts["CutTotalSeconds"]), med["SetupSeconds"], med["GeodesicSeconds"], solve,
                    med["VoxelRefinementSeconds"]))
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
