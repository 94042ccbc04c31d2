"""Other seeds on the same cases (pvpython): how the defaults hold on seeds they were not chosen on.

usage: pvpython scripts/benchmark_seeds.py [--draws 5] [--cases a,b] [--multilabel | --held-out] [--generator 0]
                                           [--methods supervoxel,voxel,random_walker,watershed]
                                           [--cut SeedElementRadius=0] [--out out/benchmark_seeds]
The shared seed files are one draw of a fixed generator (the shared data's README: object seeds at
random from the reference eroded by 2 voxels, background seeds from the band 3-15 voxels around it).
Every default was measured on those files; cases that are not shared come with their own draw. This
benchmark draws --draws new seed sets per case the same way (as many seeds of each kind as the
files hold; metrics.draw_seeds, numpy's generator seeded by --generator and the case's name) and
runs each method on each, with the case's task. Draw 0 is the seed files. The super-voxel cut
re-cuts one mesh per case (stages 1 -> 2 -> 3 do not read the seeds); the other methods run afresh.
--multilabel runs the multi-label cases instead (their README: 5 seeds per label from the label
eroded by 2 voxels, 20 background seeds from the band 3-15 voxels around the labels' union; as many
per label as seeds.csv holds), the methods of benchmark_multilabel.py, and scores each draw by the
mean of its labels' Dice (the smallest label's in the CSV).
--held-out runs object cases that no default was chosen on, made from the multi-label cases'
references (featuremesh.held_out): each abdomen organ but the liver (the liver case's own image), and
BraTS's tumour core (core + enhancing) and enhancing tumour on T1c, the regions BraTS scores
beside the whole tumour (the binary cases' object, on FLAIR). Each gets the binary cases' 10 object
and 20 background seeds from the generator rule, and Task Object.

Per case and method: Dice on the files, the mean, smallest and largest over the new draws, and on
how many draws the super-voxel cut is at least the method's Dice (at least the voxel cut's - 0.01
for the voxel cut, issue 26's rule). Writes OUT.md and OUT.csv (a row per case, draw and method).
"""
import argparse
import csv
import os
import tempfile
import time
import zlib

import numpy as np

import featuremesh as fm
from featuremesh import held_out, metrics, report
from benchmark_clicks import METHODS, Loop, file_seeds, parse_methods
import benchmark_multilabel as ml


def run_case(case, methods, draws, generator, cut):
    image = fm.fetch(case.image)
    shape = image.GetDimensions()[::-1]
    truth = case.truth().reshape(shape).astype(bool)
    files = file_seeds(case, image)
    rng = np.random.default_rng([generator, zlib.crc32(case.name.encode())])
    try:
        seed_sets = [files] + [metrics.draw_seeds(truth, len(files[0]), len(files[1]), rng) for _ in range(draws)]
    except ValueError as e:
        print("%s: no new draws (%s); the seed files only" % (case.name, e))
        seed_sets = [files]
    rows = []
    for method in methods:
        loop = Loop(method, case, image, cut if method == "supervoxel" else None)
        for d, (obj, bg) in enumerate(seed_sets):
            mask, seconds = loop.segment(obj, bg)
            rows.append({"case": case.name, "task": case.task or "", "draw": d, "method": method,
                         "dice": fm.dice(mask, truth), "seconds": seconds})
            print("%s draw %d %s: Dice %.3f (%.2f s)" % (case.name, d, method, rows[-1]["dice"], seconds), flush=True)
        loop.close()
    return rows


def run_multilabel_case(case, methods, draws, generator, cut, tmp):
    import paraview.simple as ps
    image = fm.fetch(case.image)
    shape = image.GetDimensions()[::-1]
    spacing = np.asarray(image.GetSpacing())
    truth = case.truth().reshape(shape)
    k = int(truth.max())
    files = {}
    for kk, jj, ii, label in ml.seed_index(image, case.seed_rows()):
        files.setdefault(label, []).append((ii, jj, kk))
    counts = {label: len(v) for label, v in files.items()}
    rng = np.random.default_rng([generator, zlib.crc32(case.name.encode())])
    try:
        seed_sets = [files] + [metrics.draw_labelled_seeds(truth, counts, rng) for _ in range(draws)]
    except ValueError as e:
        print("%s: no new draws (%s); the seed files only" % (case.name, e))
        seed_sets = [files]
    values = fm.v2n(image.GetPointData().GetArray(case.array)).reshape(-1, case.channels)
    unit = ml.unit_channels(values, shape, case.channels) if {"random_walker", "watershed"} & set(methods) else None
    # The cuts are made once and re-cut with each draw's seeds (the super-voxel cut keeps its mesh's data).
    cuts = {}
    if "supervoxel" in methods:
        cuts["supervoxel"] = case.super_voxel_cut(case.mesh(), **cut)
    if "voxel" in methods:
        cuts["voxel"] = case.voxel_cut()
    rows = []
    for d, seeds in enumerate(seed_sets):
        index = [(kk, j, i, label) for label in sorted(seeds) for i, j, kk in seeds[label]]
        path = os.path.join(tmp, "%s-%d.csv" % (case.name, d))
        ml.write_seeds(path, [image.GetPoint(image.ComputePointId([i, j, kk])) + (label,) for kk, j, i, label in index])
        reader = ps.CSVReader(FileName=[path])
        for method in methods:
            if method in cuts:
                cuts[method].Seeds = reader
                t = time.perf_counter()
                cuts[method].UpdatePipeline()
                seconds = time.perf_counter() - t
                result = fm.labels(cuts[method], 2 if method == "supervoxel" else 0)
            elif method == "random_walker":
                result, seconds = ml.random_walker(unit, ml.markers(shape, index), spacing)
            else:
                result, seconds = ml.watershed(unit, ml.markers(shape, index))
            per_label = ml.per_label_dice(result, truth.ravel(), k)
            rows.append({"case": case.name, "task": "labels", "draw": d, "method": method,
                         "dice": float(np.mean(per_label)), "smallest": float(min(per_label)), "seconds": seconds})
            print("%s draw %d %s: mean Dice %.3f, smallest label %.3f (%.2f s)" % (
                case.name, d, method, rows[-1]["dice"], rows[-1]["smallest"], seconds), flush=True)
    for p in ps.GetSources().values():
        ps.Delete(p)
    return rows


def summary(rows, methods):
    """Markdown lines: per case and method the files' Dice, the new draws' mean / min / max, and the
    draws on which the super-voxel cut holds against the method."""
    lines = ["| case | task | method | seed files | new draws: mean | min | max | super-voxel holds | smallest label: files / new draws' mean |",
             "|---|---|---|---|---|---|---|---|---|"]
    cases = list(dict.fromkeys(r["case"] for r in rows))
    for name in cases:
        by = {(r["method"], r["draw"]): r["dice"] for r in rows if r["case"] == name}
        least = {(r["method"], r["draw"]): r["smallest"] for r in rows if r["case"] == name and "smallest" in r}
        draws = sorted({d for (_, d) in by if d > 0})
        task = next(r["task"] for r in rows if r["case"] == name)
        for method in methods:
            new = [by[(method, d)] for d in draws if (method, d) in by]
            holds = ""
            if method != "supervoxel" and ("supervoxel", 0) in by and new:
                margin = 0.01 if method == "voxel" else 0.0
                won = sum(by[("supervoxel", d)] >= by[(method, d)] - margin for d in draws)
                holds = "%d of %d" % (won, len(draws))
            small = [least[(method, d)] for d in draws if (method, d) in least]
            smallest = "%.3f / %.3f" % (least[(method, 0)], np.mean(small)) if (method, 0) in least and small else ""
            lines.append("| %s | %s | %s | %.3f | %s | %s | %s | %s | %s |" % (
                name, task, method, by.get((method, 0), float("nan")),
                "%.3f" % np.mean(new) if new else "", "%.3f" % min(new) if new else "",
                "%.3f" % max(new) if new else "", holds, smallest))
    lines += ["", "| task | method | mean Dice, seed files | mean Dice, new draws |", "|---|---|---|---|"]
    for task in sorted({r["task"] for r in rows}):
        for method in methods:
            sel = [r for r in rows if r["task"] == task and r["method"] == method]
            if sel:
                lines.append("| %s | %s | %.3f | %.3f |" % (
                    task, method, np.mean([r["dice"] for r in sel if r["draw"] == 0]),
                    np.mean([r["dice"] for r in sel if r["draw"] > 0] or [float("nan")])))
    return lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=5)
    ap.add_argument("--generator", type=int, default=0)
    ap.add_argument("--cases", default="")
    ap.add_argument("--multilabel", action="store_true", help="the multi-label cases instead of the binary ones")
    ap.add_argument("--held-out", action="store_true",
                    help="object cases made from the multi-label references, on which no default was chosen")
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--cut", default="", type=fm.parse_properties,
                    help="properties of the Super-Voxel Cut, e.g. SeedElementRadius=0")
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark_seeds"))
    args = ap.parse_args()
    methods = parse_methods(args.methods)
    if args.draws < 0:
        raise SystemExit("--draws must be 0 or more")
    fm.load_plugin()
    if not os.path.isdir(os.path.join(fm.SHARED, "cases")):
        print("shared data not found at %s: only the bundled cases run" % fm.SHARED)
    if args.multilabel and args.held_out:
        raise SystemExit("--multilabel and --held-out exclude each other")
    rows = []
    scratch = tempfile.TemporaryDirectory(prefix="featuremesh-seeds-")  # removed at exit too
    tmp = scratch.name
    if args.held_out:
        folders = held_out.cases(os.path.join(tmp, "held-out"), args.cases, args.generator)
    else:
        folders = fm.multilabel_cases(args.cases) if args.multilabel else fm.cases(args.cases)
    for name, folder in folders.items():
        case = fm.MultiLabelCase(folder) if args.multilabel else fm.Case(folder)
        if case.truth() is None:
            print("%s: no truth.mha, skipped" % name)
            continue
        if args.multilabel:
            rows += run_multilabel_case(case, methods, args.draws, args.generator, args.cut, tmp)
        else:
            rows += run_case(case, methods, args.draws, args.generator, args.cut)
    scratch.cleanup()
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "task", "draw", "method", "dice", "smallest_label_dice", "seconds"])
        for r in rows:
            w.writerow([r["case"], r["task"], r["draw"], r["method"], "%.4f" % r["dice"],
                        "%.4f" % r["smallest"] if "smallest" in r else "", "%.3f" % r["seconds"]])
    lines = ["Machine: %s; %d new seed draws per case (generator %d), draw 0 = the seed files." % (
        report.machine(), args.draws, args.generator), ""] + summary(rows, methods)
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
