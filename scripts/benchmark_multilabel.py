"""Multi-label segmentation (pvpython): k objects from labelled seeds, side by side.

usage: pvpython scripts/benchmark_multilabel.py [--cases a,b] [--no-voxel] [--no-peers]
                                                [--cut ChannelModel=2,Lambda=0.3] [--out out/benchmark_multilabel]
Each multi-label case (Data/multilabel, then the shared data's multilabel/) runs the main job's
pipeline: Feature Nodes -> Delaunay Image Mesh -> Image Mesh Smoothing on the first channel, then
the Super-Voxel Cut with the labelled seeds (seeds.csv straight from the CSV reader) and every
channel. Peers on the same seeds: the Voxel Cut (alpha-expansion on the voxel grid), scikit-image's
random walker (beta 2e5 on the unit-range channels, as the binary benchmark; 2 x 2 x 2 block means
over 2 M voxels) and the seeded watershed on the summed gradient magnitude of the unit-range
channels. Per case and label: Dice of each method and the elements' oracle (each element takes the
label most of its voxels have in the truth). Per case: times, expansion moves and cycles, the binary
cut's time on the same mesh (all objects against the background, first channel) and the re-cut
after one seed edit (one seed added, as the robot user of benchmark_clicks.py adds it, at the most
interior voxel of the super-voxel result's largest error region, with the truth's label).
Writes OUT.md and OUT.csv (a row per case, method and label).
"""
import argparse
import csv
import os
import tempfile
import time

import numpy as np
from scipy import ndimage as ndi
import paraview.simple as ps

import featuremesh as fm
from featuremesh import metrics, report


def seed_index(image, rows):
    """(k, j, i, label) of each seed row (x, y, z, label)."""
    out = []
    for x, y, z, label in rows:
        ijk = [0.0, 0.0, 0.0]
        image.TransformPhysicalPointToContinuousIndex([x, y, z], ijk)
        i, j, k = (int(np.floor(c + 0.5)) for c in ijk)
        out.append((k, j, i, label))
    return out


def markers(shape, index):
    m = np.zeros(shape, np.int32)
    for k, j, i, label in index:
        m[k, j, i] = label + 1  # scikit-image: 0 = unlabelled
    return m


def unit_channels(values, shape, channels):
    return np.stack([metrics.unit_range(values[:, c].reshape(shape)) for c in range(channels)], axis=-1)


def random_walker(unit, seeds, spacing):
    from skimage.segmentation import random_walker as walk
    t = time.perf_counter()
    scale = 2 if unit[..., 0].size > metrics.RANDOM_WALKER_FULL_SIZE else 1
    image, m, sp = unit, seeds, np.asarray(spacing, float)
    if scale > 1:
        image = np.stack([metrics._block_mean(unit[..., c], scale) for c in range(unit.shape[-1])], axis=-1)
        m = np.zeros(image.shape[:-1], np.int32)
        z, y, x = np.nonzero(seeds)
        m[z // scale, y // scale, x // scale] = seeds[z, y, x]
        sp = sp * scale
    squeeze = image.shape[0] == 1
    r = walk(image[0] if squeeze else image, m[0] if squeeze else m, beta=metrics.RANDOM_WALKER_BETA, mode="cg_j", tol=1e-3,
             spacing=metrics._skimage_spacing(image[..., 0], sp), channel_axis=-1)
    r = r.reshape(image.shape[:-1]) - 1
    if scale > 1:
        r = r.repeat(scale, 0).repeat(scale, 1).repeat(scale, 2)[: unit.shape[0], : unit.shape[1], : unit.shape[2]]
    return r.ravel(), time.perf_counter() - t


def watershed(unit, seeds):
    from skimage.segmentation import watershed as shed
    t = time.perf_counter()
    gradient = sum(ndi.gaussian_gradient_magnitude(unit[..., c], 1.0) for c in range(unit.shape[-1]))
    return (shed(gradient, seeds) - 1).ravel(), time.perf_counter() - t


def per_label_dice(result, truth, k):
    return [fm.dice(result == l, truth == l) for l in range(1, k + 1)]


def oracle(ids, truth, k):
    ok = ids >= 0
    count = np.zeros((ids.max() + 1, k + 1))
    np.add.at(count, (ids[ok], truth[ok].astype(int)), 1)
    best = count.argmax(1)
    return np.where(ok, best[np.maximum(ids, 0)], 0)


def robot_seed(result, truth, shape, spacing):
    """(k, j, i, label): the most interior voxel of the largest wrong region, with its true label."""
    wrong = (result != truth).reshape(shape)
    regions, n = ndi.label(wrong)
    if n == 0:
        return None
    largest = regions == (int(np.argmax(np.bincount(regions.ravel())[1:])) + 1)
    distance = ndi.distance_transform_edt(np.pad(largest, 1), sampling=spacing[::-1])[1:-1, 1:-1, 1:-1]
    k, j, i = np.unravel_index(int(np.argmax(distance)), shape)
    return k, j, i, int(truth.reshape(shape)[k, j, i])


def write_seeds(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["x", "y", "z", "label"])
        w.writerows(rows)


def field(proxy, name, port=2):
    a = fm.fetch(proxy, port).GetFieldData().GetArray(name)
    return a.GetValue(0) if a else float("nan")


def run_case(name, folder, args, tmp):
    case = fm.MultiLabelCase(folder)
    vtk_image = fm.fetch(case.image)
    dims = vtk_image.GetDimensions()
    shape = (dims[2], dims[1], dims[0])
    spacing = np.asarray(vtk_image.GetSpacing())
    truth = case.truth()
    k = int(truth.max())
    rows = case.seed_rows()
    index = seed_index(vtk_image, rows)
    out = {"case": name, "labels": case.names, "dice": {}, "seconds": {}}

    t = time.perf_counter()
    mesh = case.mesh()
    mesh.UpdatePipeline()
    out["seconds"]["mesh"] = time.perf_counter() - t
    cut = case.super_voxel_cut(mesh, SuperVoxelIds=1, **args.cut)
    t = time.perf_counter()
    cut.UpdatePipeline()
    out["seconds"]["supervoxel"] = time.perf_counter() - t
    result = fm.labels(cut)
    ids = fm.v2n(fm.fetch(cut, 2).GetPointData().GetArray(fm.names.ElementId))
    out["elements"] = int(ids.max()) + 1
    out["dice"]["supervoxel"] = per_label_dice(result, truth, k)
    out["dice"]["oracle"] = per_label_dice(oracle(ids, truth, k), truth, k)
    out["moves"] = field(cut, fm.names.ExpansionMoves)
    out["cycles"] = field(cut, fm.names.ExpansionCycles)
    out["expansion_s"] = field(cut, fm.names.ExpansionSeconds)
    out["geodesic_s"] = field(cut, fm.names.GeodesicSeconds)

    # One seed edit: the mesh and its prepared data are kept, only the cut re-runs, at the default
    # outputs (the element ids were for the oracle only).
    cut.SuperVoxelIds = 0
    added = robot_seed(result, truth, shape, spacing)
    if added is not None:
        kk, jj, ii, label = added
        x, y, z = vtk_image.GetPoint(vtk_image.ComputePointId([ii, jj, kk]))
        path = os.path.join(tmp, name + "-edit.csv")
        write_seeds(path, [r for r in rows] + [(x, y, z, label)])
        cut.Seeds = ps.CSVReader(FileName=[path])
        t = time.perf_counter()
        cut.UpdatePipeline()
        out["seconds"]["recut"] = time.perf_counter() - t
        out["recut_cut_s"] = field(cut, fm.names.CutTotalSeconds)
        out["recut_refinement_s"] = field(cut, fm.names.VoxelRefinementSeconds)
        out["dice"]["supervoxel+1 seed"] = per_label_dice(fm.labels(cut), truth, k)

    # The binary cut on the same mesh: every object against the background, first channel.
    path = os.path.join(tmp, name + "-binary.csv")
    write_seeds(path, [(x, y, z, min(label, 1)) for x, y, z, label in rows])
    binary = ps.SuperVoxelCut(Mesh=mesh, Seeds=ps.CSVReader(FileName=[path]), Image=case.first, Scalars=case.first_scalars)
    t = time.perf_counter()
    binary.UpdatePipeline()
    out["seconds"]["binary"] = time.perf_counter() - t

    if not args.no_voxel:
        voxel = case.voxel_cut(**args.cut)
        t = time.perf_counter()
        voxel.UpdatePipeline()
        out["seconds"]["voxel"] = time.perf_counter() - t
        out["dice"]["voxel"] = per_label_dice(fm.labels(voxel, 0), truth, k)
    if not args.no_peers:
        values = fm.v2n(vtk_image.GetPointData().GetArray(case.array)).reshape(-1, case.channels)
        unit = unit_channels(values, shape, case.channels)
        m = markers(shape, index)
        r, s = random_walker(unit, m, spacing)
        out["dice"]["random_walker"], out["seconds"]["random_walker"] = per_label_dice(r, truth, k), s
        r, s = watershed(unit, m)
        out["dice"]["watershed"], out["seconds"]["watershed"] = per_label_dice(r, truth, k), s
    for p in ps.GetSources().values():
        ps.Delete(p)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", default="")
    ap.add_argument("--no-voxel", action="store_true")
    ap.add_argument("--no-peers", action="store_true")
    ap.add_argument("--cut", default="", type=fm.parse_properties, help="properties of both cuts, e.g. ChannelModel=2")
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark_multilabel"))
    args = ap.parse_args()
    fm.load_plugin()
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, folder in fm.multilabel_cases(args.cases).items():
            results.append(run_case(name, folder, args, tmp))
            print(name, {m: round(float(np.mean(d)), 3) for m, d in results[-1]["dice"].items()}, flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    methods = ["supervoxel", "supervoxel+1 seed", "voxel", "random_walker", "watershed", "oracle"]
    lines = ["# Multi-label segmentation", "", report.machine(), "",
             "Dice per label (mean over the labels last); the oracle is the mesh's limit.", ""]
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "method", "label", "name", "dice"])
        for r in results:
            present = [m for m in methods if m in r["dice"]]
            lines += ["## " + r["case"], "", "| label | " + " | ".join(present) + " |", "|---" * (len(present) + 1) + "|"]
            for l, label_name in enumerate(r["labels"][1:], start=1):
                lines.append("| %d %s | " % (l, label_name) + " | ".join("%.3f" % r["dice"][m][l - 1] for m in present) + " |")
                for m in present:
                    w.writerow([r["case"], m, l, label_name, "%.4f" % r["dice"][m][l - 1]])
            lines.append("| mean | " + " | ".join("**%.3f**" % np.mean(r["dice"][m]) for m in present) + " |")
            sec = r["seconds"]
            lines += ["", "Elements %d; expansion moves %d in %d cycles; seconds: " % (r["elements"], r["moves"], r["cycles"]) +
                      ", ".join("%s %.3f" % (key, v) for key, v in sec.items()) +
                      "; expansion %.3f, geodesic %.3f; the re-cut's own time %.3f (its voxel refinement %.3f);"
                      " multi-label / binary cut %.2f." %
                      (r["expansion_s"], r["geodesic_s"], r.get("recut_cut_s", float("nan")),
                       r.get("recut_refinement_s", float("nan")), sec["supervoxel"] / sec["binary"]), ""]
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
