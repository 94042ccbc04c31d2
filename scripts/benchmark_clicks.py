"""The interactive loop (pvpython): a robot user adds one seed per round where the result is most
wrong, as in the standard protocol of interactive segmentation (NoC@85 / NoC@90: Xu et al., "Deep
interactive object selection", CVPR 2016).

usage: pvpython scripts/benchmark_clicks.py [--rounds 10] [--cases a,b] [--methods supervoxel,voxel,random_walker,watershed]
                                            [--cut VoxelRefinement=0] [--held-out] [--out out/benchmark_clicks]
Each case starts from its seed files and runs with its task (cases.csv). Each round: the largest
connected error region of the current result (face-connected; false positives and false negatives
apart), one seed at its most interior voxel (largest distance to the region's border, in world
units; the first in raster order on ties): a background seed in a false positive, an object seed in
a false negative; then the method segments again. Up to --rounds rounds (fewer when nothing is
wrong). Methods: the super-voxel cut re-cutting its kept mesh (stages 1 -> 2 -> 3 made once, as in
the GUI; only the cut re-runs), the voxel cut, scikit-image's random walker and the seeded watershed
on the gradient (featuremesh.metrics), each re-run from all seeds every round. --held-out runs the
held-out object cases instead (featuremesh.held_out: made from the multi-label references, on which no
default was chosen).

Per method and case: Dice after each round (round 0 = the seed files), NoC@85 and NoC@90 (rounds
to reach the Dice; 0 when the seed files do, rounds + 1 when never), the median seconds of a round,
the seeds that lost their label and the largest fall of Dice in a round. Writes OUT.md, OUT.csv
(a row per method, case and round).
"""
import argparse
import csv
import os
import statistics
import tempfile
import time

import numpy as np
import paraview.simple as ps

import featuremesh as fm
from featuremesh import held_out, metrics, report

METHODS = ("supervoxel", "voxel", "random_walker", "watershed")


def parse_methods(text):
    """The --methods list; exits with a message on an unknown name."""
    methods = [m for m in text.split(",") if m]
    unknown = [m for m in methods if m not in METHODS]
    if unknown:
        raise SystemExit("unknown methods: %s (choose from %s)" % (", ".join(unknown), ", ".join(METHODS)))
    return methods


class Loop:
    """One method's segmentation from (object, background) seed index lists ((i, j, k) each)."""

    def __init__(self, method, case, image, cut=None):
        self.method, self.case = method, case
        self.origin, self.spacing = np.array(image.GetOrigin()), np.array(image.GetSpacing())
        self.shape = image.GetDimensions()[::-1]
        if method in ("supervoxel", "voxel"):
            self.object = ps.PolyPointSource()
            self.background = ps.PolyPointSource()
            if method == "supervoxel":
                mesh = case.smoothing(case.mesh(case.feature_nodes()))
                mesh.UpdatePipeline()
                self.proxy = ps.SuperVoxelCut(Mesh=mesh, ObjectSeeds=self.object, BackgroundSeeds=self.background,
                                              Image=case.image, Scalars=case.scalars, **case.with_task(dict(cut or {})))
            else:
                self.proxy = ps.VoxelCut(Input=case.image, ObjectSeeds=self.object, BackgroundSeeds=self.background,
                                         Scalars=case.scalars, **case.with_task({}))
        else:
            self.unit = metrics.unit_range(fm.v2n(image.GetPointData().GetScalars()).reshape(self.shape))

    def world(self, seeds):
        return [float(c) for s in seeds for c in self.origin + np.asarray(s) * self.spacing]

    def segment(self, object_seeds, background_seeds):
        """(mask in (k, j, i) order, seconds)."""
        if self.method in ("supervoxel", "voxel"):
            self.object.Points = self.world(object_seeds)
            self.background.Points = self.world(background_seeds)
            t = time.perf_counter()
            self.proxy.UpdatePipeline()
            seconds = time.perf_counter() - t
            return fm.labels(self.proxy, 2 if self.method == "supervoxel" else 0).reshape(self.shape).astype(bool), seconds
        markers = metrics.seed_markers(self.shape, object_seeds, background_seeds)
        peer = metrics.random_walker_peer if self.method == "random_walker" else metrics.watershed_peer
        mask, seconds, _ = peer(self.unit, markers, self.spacing)
        return mask.reshape(self.shape), seconds

    def close(self):
        if self.method in ("supervoxel", "voxel"):
            ps.Delete(self.proxy)


def file_seeds(case, image):
    """(object, background) seed lists of the case's seed files, as (i, j, k) voxel indices."""
    origin, spacing = np.array(image.GetOrigin()), np.array(image.GetSpacing())
    seeds = []
    for name in ("seeds_object.csv", "seeds_background.csv"):
        pts = np.loadtxt(os.path.join(case.folder, name), delimiter=",", skiprows=1, ndmin=2)
        seeds.append([tuple(int(v) for v in s) for s in np.rint((pts - origin) / spacing)])
    return seeds


def noc(dices, target, rounds):
    hit = [r for r, d in enumerate(dices) if d >= target]
    return hit[0] if hit else rounds + 1


def run(case, method, rounds, cut=None):
    image = fm.fetch(case.image)
    truth = case.truth().reshape(image.GetDimensions()[::-1]).astype(bool)
    spacing = np.array(image.GetSpacing())
    object_seeds, background_seeds = file_seeds(case, image)
    loop = Loop(method, case, image, cut)
    dices, seconds, lost, added = [], [], 0, []
    for r in range(rounds + 1):
        mask, t = loop.segment(object_seeds, background_seeds)
        dices.append(fm.dice(mask, truth))
        seconds.append(t)
        # Every seed the robot added keeps its label.
        lost += sum(int(mask[k, j, i] != is_object) for (i, j, k), is_object in added)
        if r == rounds:
            break
        found = metrics.next_seed(mask, truth, spacing)
        if found is None:
            break
        (k, j, i), is_object = found
        (object_seeds if is_object else background_seeds).append((int(i), int(j), int(k)))
        added.append(((int(i), int(j), int(k)), is_object))
    loop.close()
    falls = [dices[r] - dices[r + 1] for r in range(len(dices) - 1)]
    return {"case": case.name, "task": case.task or "", "method": method, "dice": dices,
            "noc85": noc(dices, 0.85, rounds), "noc90": noc(dices, 0.90, rounds),
            # The first round of the super-voxel cut includes preparing the mesh's data; later ones re-cut.
            "round_s": statistics.median(seconds[1:] if len(seconds) > 1 else seconds),
            "lost_seeds": lost, "largest_fall": max(falls) if falls else 0.0}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=10)
    ap.add_argument("--cases", default="")
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--cut", default="", type=fm.parse_properties,
                    help="properties of the Super-Voxel Cut, e.g. VoxelRefinement=0")
    ap.add_argument("--held-out", action="store_true", help="the held-out object cases (featuremesh.held_out)")
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark_clicks"))
    args = ap.parse_args()
    methods = parse_methods(args.methods)
    fm.load_plugin()
    if not os.path.isdir(os.path.join(fm.SHARED, "cases")):
        print("shared data not found at %s: only the bundled cases run" % fm.SHARED)
    rows = []
    scratch = tempfile.TemporaryDirectory(prefix="featuremesh-clicks-")  # removed at exit too
    if args.held_out:
        folders = held_out.cases(os.path.join(scratch.name, "held-out"), args.cases, 0)
    else:
        folders = fm.cases(args.cases)
    for name, folder in folders.items():
        case = fm.Case(folder)
        if case.truth() is None:
            print("%s: no truth.mha, skipped" % name)
            continue
        for method in methods:
            row = run(case, method, args.rounds, args.cut if method == "supervoxel" else None)
            rows.append(row)
            print("%s %s (%s): Dice %s, NoC@85 %d, NoC@90 %d, round %.3f s, lost seeds %d" % (
                name, method, row["task"], " ".join("%.3f" % d for d in row["dice"]), row["noc85"], row["noc90"],
                row["round_s"], row["lost_seeds"]), flush=True)
    scratch.cleanup()
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "task", "method", "round", "dice", "noc85", "noc90", "round_s", "lost_seeds", "largest_fall"])
        for r in rows:
            for k, d in enumerate(r["dice"]):
                w.writerow([r["case"], r["task"], r["method"], k, "%.4f" % d, r["noc85"], r["noc90"], "%.4f" % r["round_s"],
                            r["lost_seeds"], "%.4f" % r["largest_fall"]])
    lines = ["Machine: %s; %d rounds at most." % (report.machine(), args.rounds), "",
             "| case | task | method | Dice round 0 | Dice last | Dice per round | NoC@85 | NoC@90 | s/round | lost seeds | largest fall |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| %s | %s | %s | %.3f | %.3f | %s | %d | %d | %.3f | %d | %.3f |" % (
            r["case"], r["task"], r["method"], r["dice"][0], r["dice"][-1], " ".join("%.2f" % d for d in r["dice"]),
            r["noc85"], r["noc90"], r["round_s"], r["lost_seeds"], r["largest_fall"]))
    # The family means: object cases and class cases apart.
    lines += ["", "| task | method | mean Dice round 0 | mean Dice last | mean NoC@85 | mean NoC@90 |", "|---|---|---|---|---|---|"]
    for task in sorted({r["task"] for r in rows}):
        for method in methods:
            sel = [r for r in rows if r["task"] == task and r["method"] == method]
            if sel:
                lines.append("| %s | %s | %.3f | %.3f | %.1f | %.1f |" % (
                    task, method, np.mean([r["dice"][0] for r in sel]), np.mean([r["dice"][-1] for r in sel]),
                    np.mean([r["noc85"] for r in sel]), np.mean([r["noc90"] for r in sel])))
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
