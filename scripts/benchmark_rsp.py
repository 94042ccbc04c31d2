"""Stage 5 benchmark (pvpython): RSP Edge Enhancement, and seed-aware nodes against Canny nodes.

usage: pvpython scripts/benchmark_rsp.py [--cases a,b] [--rsp K=V,...] [--nodes K=V,...] [--no-slic]
                                         [--runs 1] [--out out/benchmark_rsp]
For every case with a truth (bundled Data/ and ../shared/data/cases):
- the edge confidence (EC): the filter's seconds (median of --runs), its path grid, and the EC ratio:
  mean EC within 1 voxel of the reference boundary (the object voxels with a background face
  neighbour, and those neighbours) over the mean EC farther than 5 voxels from it;
- the pipeline 1 -> 2 -> 3 -> 4 at the defaults with Canny nodes (today's) and with RSP-driven,
  seed-aware nodes (RSP Edge Enhancement's output on Feature Nodes' Edge Map): elements, the oracle
  Dice of the elements (each takes its majority reference label), SLIC (scikit-image) at the RSP
  mesh's element count (featuremesh.metrics.slic_at_count), and the super-voxel cut's Dice.
Writes OUT.md and OUT.csv.
"""
import argparse
import csv
import os
import statistics
import time

import numpy as np
import paraview.simple as ps
from scipy import ndimage
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

import featuremesh as fm
from featuremesh import metrics


def parse(text):
    out = {}
    for kv in filter(None, (text or "").split(",")):
        k, v = kv.split("=")
        out[k] = float(v) if any(c in v for c in ".e") else int(v)
    return out


def ec_ratio(ec, truth):
    """Mean EC within 1 voxel of the reference boundary over the mean EC farther than 5 voxels."""
    inner = truth & ~ndimage.binary_erosion(truth)
    outer = ndimage.binary_dilation(truth) & ~truth
    d = ndimage.distance_transform_edt(~(inner | outer))
    near, far = ec[d <= 1].mean(), ec[d > 5].mean()
    return near / far if far > 0 else float("inf"), near, far


def timed(proxy):
    t = time.perf_counter()
    proxy.UpdatePipeline()
    return time.perf_counter() - t


def mesh_scores(case, edges, truth, shape, nodes_props):
    nodes = case.feature_nodes(edges, **nodes_props) if edges is not None else case.feature_nodes()
    mesh = case.smoothing(case.mesh(nodes))
    cut = case.super_voxel_cut(mesh)
    cut.UpdatePipeline()
    owner = fm.element_owners(mesh)
    scores = metrics.partition_scores(owner.reshape(shape), truth)
    out = {"elements": fm.fetch(mesh).GetNumberOfCells(), "K": scores["K"], "oracle": scores["oracle_dice"],
           "dice": fm.dice(fm.labels(cut), truth.ravel()), "elements_dice": fm.dice(fm.element_labels(cut, mesh, owner), truth.ravel())}
    for p in (cut, mesh, nodes):
        ps.Delete(p)
    return out


def run_case(case, args):
    image = fm.fetch(case.image)
    shape = image.GetDimensions()[::-1]
    truth = case.truth().reshape(shape).astype(bool)
    seconds = []
    for _ in range(args.runs):
        rsp = case.rsp(**parse(args.rsp))
        seconds.append(timed(rsp))
    out = fm.fetch(rsp)
    ec = v2n(out.GetPointData().GetArray(fm.names.EdgeConfidence)).reshape(shape)
    ratio, near, far = (float(v) for v in ec_ratio(ec, truth))
    fd = out.GetFieldData()
    row = {"case": case.name, "rsp_s": statistics.median(seconds), "path_grid": int(fd.GetArray(fm.names.PathGridFactor).GetValue(0)),
           "ec_ratio": ratio, "ec_near": near, "ec_far": far,
           "edge_voxels": int(v2n(out.GetPointData().GetArray(fm.names.EdgeMap)).sum())}
    canny = mesh_scores(case, None, truth, shape, {})
    seeded = mesh_scores(case, rsp, truth, shape, parse(args.nodes))
    row.update({"elements_canny": canny["elements"], "elements_rsp": seeded["elements"],
                "oracle_canny": canny["oracle"], "oracle_rsp": seeded["oracle"],
                "dice_canny": canny["dice"], "dice_rsp": seeded["dice"],
                "dice_elements_canny": canny["elements_dice"], "dice_elements_rsp": seeded["elements_dice"]})
    if not args.no_slic:
        unit = metrics.unit_range(v2n(image.GetPointData().GetScalars()).reshape(shape))
        slic = metrics.slic_at_count(unit, truth, seeded["K"], image.GetSpacing())
        row["oracle_slic_at_rsp_K"] = slic["oracle_dice"]
    ps.Delete(rsp)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="")
    ap.add_argument("--rsp", default="", help="RSP Edge Enhancement properties, K=V,...")
    ap.add_argument("--nodes", default="", help="Feature Nodes properties for the RSP-driven run, K=V,...")
    ap.add_argument("--runs", type=int, default=1)
    ap.add_argument("--no-slic", action="store_true")
    ap.add_argument("--out", default=os.path.join(fm.ROOT, "out", "benchmark_rsp"))
    args = ap.parse_args()
    fm.load_plugin()
    rows = []
    for name, folder in fm.cases(args.cases).items():
        if not os.path.isfile(os.path.join(folder, "truth.mha")):
            continue
        rows.append(run_case(fm.Case(folder), args))
        print(" ".join(f"{k}={v:.4g}" if isinstance(v, (float, np.floating)) else f"{k}={v}" for k, v in rows[-1].items()), flush=True)
    if not rows:
        raise SystemExit("no cases with a truth found (../shared/data absent?)")
    keys = list(rows[0].keys())
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    with open(args.out + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, keys)
        w.writeheader()
        w.writerows(rows)
    fmt = lambda v: f"{v:.3f}" if isinstance(v, (float, np.floating)) else str(v)  # noqa: E731
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(fmt(r.get(k, "")) for k in keys) + " |" for r in rows]
    with open(args.out + ".md", "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
