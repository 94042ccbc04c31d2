"""FeatureMesh benchmark (pvpython): the segmentation against the voxel cut and seeded peers, and the
mesh as super-pixels against SLIC, on every case.

usage: pvpython scripts/benchmark.py [--runs 3] [--cases a,b] [--out out/benchmark]
                                     [--no-slic] [--no-peers] [--lambdas 0.1,0.2,0.5]
Cases: the bundled Data/ ones and every case in ../shared/data/cases (skipped with a message when
absent). Everything runs at the filters' defaults on each case's seed files.

The pipeline is stages 1 -> 2 -> 3 -> 4 at their defaults (Feature Nodes, Delaunay Image Mesh,
Image Mesh Smoothing, Super-Voxel Cut); a quality table gives the minimum and maximum (dihedral)
angle of the Delaunay mesh and of the smoothed one, and the nodes smoothing added.

Speed table: each stage's seconds and the pipeline's (median of --runs fresh runs per stage), the voxel
cut's (once when it takes over 5 s) and their ratio; in 3D the classic pipeline a user would otherwise
run, the voxel cut then CGAL Mesh_3 on its labels (FeatureMeshClassicMesh3, built with the tests;
facet distance 2, object and background meshed), and its ratio; the re-cut after a seed edit (recut_s:
the first object seed moved by one voxel, only the cut re-run) and the voxel cut's ratio to it. After
each Apply the GUI also waits for ParaView's data information of every output port (array ranges,
bounds, sizes): info_s for the four stages' outputs, recut_info_s for the re-cut's.

Segmentation table: Dice of the pipeline, the voxel cut, scikit-image's random walker (image mapped to [0, 1] by its
0.5/99.5 percentiles, so that one beta means the same on every image: 2e5, featuremesh.metrics; over 2 M voxels on 2 x 2 x 2
block means, random_walker_scale 2) and a seeded watershed on
the gradient magnitude (sigma 1 voxel) of that image; the peers get the same seed voxels.

Super-pixel table: the mesh's elements as super-pixels (K, oracle Dice = each element takes its
majority reference label, ASA, boundary recall within 1 voxel) and SLIC at the same K: each
compactness of 0.01/0.03/0.1/0.3 (on the [0, 1] image) runs near K, the best by oracle Dice runs
again on the other side of K and the scores are interpolated to K.

--lambdas adds a table of the Super-Voxel Cut's and the Voxel Cut's Dice over lambda, for each
connectivity rule, on the same meshes. Writes OUT.md and OUT.csv (and OUT_lambda.csv).
"""
import argparse
import csv
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

import featuremesh as fm
from featuremesh import metrics, report

CONNECTIVITY = {0: "off", 1: "fill", 2: "seeded"}


def field(data, name):
    a = data.GetFieldData().GetArray(name)
    return v2n(a) if a is not None else np.zeros(0)


def seed_indices(case, image):
    """Voxel (i, j, k) of every seed of the case (the shared data have identity directions)."""
    origin, spacing = np.array(image.GetOrigin()), np.array(image.GetSpacing())
    out = []
    for name in ("seeds_object.csv", "seeds_background.csv"):
        pts = np.loadtxt(os.path.join(case.folder, name), delimiter=",", skiprows=1, ndmin=2)
        out.append(np.rint((pts - origin) / spacing).astype(int))
    return out


def cells_of(grid):
    return v2n(grid.GetCells().GetConnectivityArray()).reshape(grid.GetNumberOfCells(), -1)


def timed(proxy):
    t = time.perf_counter()
    proxy.UpdatePipeline()
    return time.perf_counter() - t


def information_seconds(proxy):
    """Seconds ParaView takes to gather the data information of every output port, as the GUI
    does after an Apply (the Information panel, the representations' colour ranges)."""
    t = time.perf_counter()
    for port in range(proxy.GetNumberOfOutputPorts()):
        proxy.GetDataInformation(port).GetNumberOfPoints()
    return time.perf_counter() - t


def classic_mesh3(labels, image):
    """Seconds of CGAL Mesh_3 on a voxel cut's labels (FeatureMeshClassicMesh3, built with the tests;
    object and background both meshed, facet distance 2), or None when the program is absent."""
    exe = os.environ.get("FEATUREMESH_CLASSIC_MESH3", os.path.join(fm.ROOT, "build", "Testing", "FeatureMeshClassicMesh3"))
    if not os.path.exists(exe):
        print("classic pipeline: %s not found (build the tests)" % exe)
        return None
    with tempfile.NamedTemporaryFile(suffix=".raw") as f:
        labels.astype(np.uint8).tofile(f.name)
        args = [exe, f.name] + [str(d) for d in image.GetDimensions()] + [str(abs(s)) for s in image.GetSpacing()] + ["2"]
        out = subprocess.run(args, capture_output=True, text=True, check=True).stdout.split()
    return float(out[out.index("seconds") + 1])


def run_case(case, args):
    T = case.truth()
    image = fm.fetch(case.image)
    dims, spacing = image.GetDimensions(), image.GetSpacing()
    shape = dims[::-1]
    truth = T.reshape(shape).astype(bool)
    # Fresh proxies every run: re-executing a proxy would only measure ParaView's cache.
    times = {"nodes": [], "mesh": [], "smoothing": [], "cut": []}
    info = []
    for _ in range(args.runs):
        nodes = case.feature_nodes()
        delaunay = case.mesh(nodes)
        mesh = case.smoothing(delaunay)
        cut = case.super_voxel_cut(mesh)
        case.object_seeds.UpdatePipeline()
        case.background_seeds.UpdatePipeline()
        for key, proxy in (("nodes", nodes), ("mesh", delaunay), ("smoothing", mesh), ("cut", cut)):
            times[key].append(timed(proxy))
        info.append(sum(information_seconds(proxy) for proxy in (nodes, delaunay, mesh, cut)))
    labelled = fm.fetch(cut, 0)
    L = fm.labels(cut)
    owners = fm.element_owners(mesh)
    # Re-cut after a seed edit: the same mesh, the first object seed moved by one voxel and back;
    # only the cut re-runs (it keeps what depends on the mesh alone).
    seeds = fm.fetch(case.object_seeds)
    points = [c for i in range(seeds.GetNumberOfPoints()) for c in seeds.GetPoint(i)]
    edited = ps.PolyPointSource(Points=points)
    recut = ps.SuperVoxelCut(Mesh=mesh, ObjectSeeds=edited, BackgroundSeeds=case.background_seeds, Image=case.image,
                             Scalars=case.scalars)
    recut.UpdatePipeline()
    rt, rti = [], []
    for k in range(max(3, args.runs)):
        points[0] += spacing[0] * (1 if k % 2 == 0 else -1)
        edited.Points = points
        rt.append(timed(recut))
        rti.append(information_seconds(recut))
    ps.Delete(recut)
    vt = []
    for _ in range(args.runs):
        vc = case.voxel_cut()
        vt.append(timed(vc))
        if vt[-1] > 5:
            break
    V = fm.labels(vc, 0)
    med = {k: statistics.median(v) for k, v in times.items()}
    total = sum(med.values())
    # The classic pipeline (3D): the voxel cut, then CGAL Mesh_3 on its labels.
    mesh3 = classic_mesh3(V, image) if dims[2] > 1 else None
    raw = fm.fetch(delaunay)
    q0 = metrics.mesh_quality(v2n(raw.GetPoints().GetData()), cells_of(raw))
    q1 = metrics.mesh_quality(v2n(labelled.GetPoints().GetData()), cells_of(labelled))
    row = {"case": case.name, "voxels": T.size, "elements": labelled.GetNumberOfCells(),
           "elements_with_voxels": int((v2n(labelled.GetCellData().GetArray(fm.names.PixelCount)) > 0).sum()),
           "nodes_s": med["nodes"], "mesh_s": med["mesh"], "smoothing_s": med["smoothing"], "cut_s": med["cut"], "total_s": total,
           "voxel_cut_s": statistics.median(vt), "speedup": statistics.median(vt) / total,
           "recut_s": statistics.median(rt), "recut_speedup": statistics.median(vt) / statistics.median(rt),
           "info_s": statistics.median(info), "recut_info_s": statistics.median(rti),
           "dice_supervoxel": fm.dice(L, T), "dice_elements": fm.dice(fm.element_labels(cut, mesh, owners), T),
           "dice_voxel": fm.dice(V, T),
           "components": int(field(labelled, "ObjectComponents")[0]),
           "added_nodes_pct": 100.0 * float(field(labelled, "AddedNodes")[0]) / raw.GetNumberOfPoints(),
           "min_angle_delaunay": q0["min"], "min_angle_smoothed": q1["min"],
           "max_angle_delaunay": q0["max"], "max_angle_smoothed": q1["max"]}
    if mesh3 is not None:
        row.update({"mesh3_s": mesh3, "classic_s": row["voxel_cut_s"] + mesh3,
                    "classic_speedup": (row["voxel_cut_s"] + mesh3) / total})
    unit = metrics.unit_range(v2n(image.GetPointData().GetScalars()).reshape(shape))
    if not args.no_peers:
        obj, bg = seed_indices(case, image)
        markers = metrics.seed_markers(shape, obj, bg)
        for key, peer in (("random_walker", metrics.random_walker_peer), ("watershed", metrics.watershed_peer)):
            mask, seconds, scale = peer(unit, markers, spacing)
            row["dice_" + key] = fm.dice(mask.ravel(), T)
            row[key + "_s"] = seconds
            if key == "random_walker":
                row["random_walker_scale"] = scale
    if not args.no_slic:
        mine = metrics.partition_scores(owners.reshape(shape), truth)
        slic = metrics.slic_at_count(unit, truth, mine["K"], spacing)
        row.update({"K": mine["K"], "oracle_dice_mesh": mine["oracle_dice"], "oracle_dice_slic": slic["oracle_dice"],
                    "asa_mesh": mine["asa"], "asa_slic": slic["asa"],
                    "boundary_recall_mesh": mine["boundary_recall"], "boundary_recall_slic": slic["boundary_recall"],
                    "slic_compactness": slic["compactness"], "slic_bracket": "%s-%s" % slic["bracket"],
                    "slic_s": slic["seconds"]})
    lam_rows = []
    for lam in args.lambdas:
        r = {"case": case.name, "lambda": lam}
        for mode, tag in CONNECTIVITY.items():
            c = case.super_voxel_cut(mesh, Lambda=lam, Connectivity=mode)
            r["supervoxel_" + tag] = fm.dice(fm.labels(c), T)
            ps.Delete(c)
            v = case.voxel_cut(Lambda=lam, Connectivity=mode)
            r["voxel_" + tag] = fm.dice(fm.labels(v, 0), T)
            ps.Delete(v)
        lam_rows.append(r)
        print("  lambda %g: %s" % (lam, " ".join("%s %.3f" % (k, v) for k, v in r.items() if k.startswith(("super", "voxel")))), flush=True)
    return row, lam_rows


def markdown(rows, keys):
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        lines.append("| " + " | ".join(("%.3f" % r[k]) if isinstance(r.get(k), float) else str(r.get(k, "")) for k in keys) + " |")
    if rows and len(rows) > 1:
        means = {k: float(np.mean([r[k] for r in rows if isinstance(r.get(k), float)])) for k in keys
                 if all(isinstance(r.get(k), float) for r in rows) and not k.endswith(("_s", "compactness"))}
        lines.append("| mean | " + " | ".join(("%.3f" % means[k]) if k in means else "" for k in keys[1:]) + " |")
    return lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cases", default="")
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark"))
    ap.add_argument("--no-slic", action="store_true", help="skip the super-pixel table")
    ap.add_argument("--no-peers", action="store_true", help="skip the random walker and watershed")
    ap.add_argument("--lambdas", default="", help="comma-separated lambdas for the lambda table")
    ap.add_argument("--hugepages", action="store_true",
                    help="run with malloc using transparent huge pages (both cuts and every library alike)")
    args = ap.parse_args()
    if args.hugepages:
        report.use_huge_pages(sys.argv)
    args.lambdas = [float(v) for v in args.lambdas.split(",") if v]
    fm.load_plugin()
    found = fm.cases(args.cases)
    if not os.path.isdir(os.path.join(fm.SHARED, "cases")):
        print("shared data not found at %s: only the bundled cases run" % fm.SHARED)
    rows, lam_rows = [], []
    for name, d in found.items():
        case = fm.Case(d)
        if case.truth() is None:
            print("%s: no truth.mha, skipped" % name)
            continue
        row, lr = run_case(case, args)
        rows.append(row)
        lam_rows += lr
        print(" | ".join("%s %s" % (k, ("%.3f" % v) if isinstance(v, float) else v) for k, v in row.items()), flush=True)
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(rows)
    machine = report.machine()
    seg = [k for k in keys if k in ("case", "components") or k.startswith("dice_") or k.endswith(("walker_s", "shed_s", "_scale"))]
    speed = [k for k in keys if k in ("case", "voxels", "elements", "nodes_s", "mesh_s", "smoothing_s", "cut_s", "total_s",
                                      "voxel_cut_s", "speedup", "mesh3_s", "classic_s", "classic_speedup", "recut_s",
                                      "recut_speedup", "info_s", "recut_info_s")]
    mq = [k for k in keys if k in ("case", "mesh_s", "smoothing_s", "added_nodes_pct") or k.startswith(("min_angle", "max_angle"))]
    sp = [k for k in keys if k == "case" or k == "K" or k.startswith(("oracle_", "asa_", "boundary_", "slic_"))]
    lines = ["Machine: %s; medians of %d runs (voxel cut: once when over 5 s)." % (machine, args.runs), "",
             "## Speed (seconds; speedup = voxel cut / pipeline, classic = voxel cut + CGAL Mesh_3 of its labels, "
             "recut = the cut after a seed edit; info = ParaView's data information of the outputs after Apply)", ""] + markdown(rows, speed)
    lines += ["", "## Segmentation (Dice at the defaults)", ""] + markdown(rows, seg)
    lines += ["", "## Mesh quality: Delaunay Image Mesh, then Image Mesh Smoothing (angles in degrees; 3D dihedral)", ""]
    lines += markdown(rows, mq)
    if len(sp) > 1:
        lines += ["", "## The mesh as super-pixels, against SLIC at the same K", ""] + markdown(rows, sp)
    if lam_rows:
        lkeys = list(lam_rows[0].keys())
        with open(args.out + "_lambda.csv", "w", newline="") as f:
            w = csv.DictWriter(f, lkeys)
            w.writeheader()
            w.writerows(lam_rows)
        lines += ["", "## Dice over lambda (connectivity off / fill holes / seeded object)", ""]
        lines += markdown(lam_rows, lkeys)[:-1] if len(lam_rows) > 1 else markdown(lam_rows, lkeys)
        means = ["| mean over cases, lambda %g | " % lam + " | ".join(
            "%.3f" % np.mean([r[k] for r in lam_rows if r["lambda"] == lam]) for k in lkeys[2:]) + " |"
            for lam in args.lambdas]
        lines += means
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
