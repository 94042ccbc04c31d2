"""How the pipeline scales with the voxel count (pvpython): BraTS-0005 at 1x, resampled to 2x the voxels
and to 512^3, each run in a fresh process so that its peak memory is its own.

usage: pvpython scripts/benchmark_scale.py [--case brain-tumour-brats-0005] [--sizes 1x,2x,512^3] [--out out/benchmark_scale]
Each size runs stages 1 -> 2 -> 3 -> 4 at their defaults on the case's seeds (world points, so they
hold on a resampled image) and reports each stage's seconds (stage 3's also split into its sweeps,
quality refinement, sliver perturbation and statistics), the total, seconds per million voxels,
the elements and the process's peak resident memory after each stage (the last is the run's peak);
then, in a second process, the seconds and peak of the same pipeline updated at once, as a script
runs it (at_once_s, at_once_peak_gb: ParaView's Apply updates one stage at a time, where stage 2
makes its owner map and stage 3 releases it). The resampled images (linear interpolation, the same first and last voxel
centres) are written to a temporary folder first. Writes OUT.md and OUT.csv.
"""
import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time

from featuremesh import report
from featuremesh.report import write_table

SIZES = (("1x", None), ("2x", 2.0 ** (1.0 / 3.0)), ("512^3", 512))


def make_image(source, target, factor):
    """Resamples `source` (.mha) over the same world box (first and last voxel centres kept, so seeds
    on its border stay inside): `factor` times the voxels per axis, or `factor` voxels per axis when
    it is an int."""
    from vtkmodules.vtkIOImage import vtkMetaImageReader, vtkMetaImageWriter
    from vtkmodules.vtkImagingCore import vtkImageReslice
    reader = vtkMetaImageReader()
    reader.SetFileName(source)
    reader.Update()
    image = reader.GetOutput()
    dims, spacing = image.GetDimensions(), image.GetSpacing()
    out = [factor if isinstance(factor, int) else int(round((d - 1) * factor)) + 1 for d in dims]
    reslice = vtkImageReslice()
    reslice.SetInputConnection(reader.GetOutputPort())
    reslice.SetInterpolationModeToLinear()
    reslice.SetOutputOrigin(image.GetOrigin())
    reslice.SetOutputSpacing([spacing[a] * (dims[a] - 1) / (out[a] - 1) for a in range(3)])
    reslice.SetOutputExtent(0, out[0] - 1, 0, out[1] - 1, 0, out[2] - 1)
    writer = vtkMetaImageWriter()
    writer.SetInputConnection(reslice.GetOutputPort())
    writer.SetFileName(target)
    writer.SetCompression(False)
    writer.Write()


def child(folder, image, at_once=False):
    import featuremesh as fm
    fm.load_plugin()
    case = fm.Case(folder, image=image)
    voxels = fm.fetch(case.image).GetNumberOfPoints()
    nodes = case.feature_nodes()
    mesh = case.mesh(nodes)
    smooth = case.smoothing(mesh)
    cut = case.super_voxel_cut(smooth)
    if at_once:
        # As a script runs it: one update of the cut (stage 3 then asks stage 2 for no owner map).
        t = time.perf_counter()
        cut.UpdatePipeline()
        print("RESULT " + json.dumps({"at_once_s": time.perf_counter() - t,
                                      "at_once_peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0 ** 2}))
        return
    row = {"voxels": voxels}
    for key, proxy in (("nodes_s", nodes), ("mesh_s", mesh), ("smoothing_s", smooth), ("cut_s", cut)):
        t = time.perf_counter()
        proxy.UpdatePipeline()
        row[key] = time.perf_counter() - t
        # The process's peak so far: which stage sets it (after the cut: peak_gb, below).
        if key != "cut_s":
            row[key[:-2] + "_peak_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0 ** 2
    # Stage 3's own timers: where its time goes as the mesh grows.
    field = fm.fetch(smooth).GetFieldData()
    for key, name in (("sweeps_s", "SweepSeconds"), ("refinement_s", "RefinementSeconds"), ("slivers_s", "SliverSeconds"),
                      ("statistics_s", "StatisticsSeconds")):
        row[key] = field.GetArray(name).GetTuple1(0)
    row["elements"] = fm.fetch(cut, 0).GetNumberOfCells()
    row["peak_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0 ** 2
    print("RESULT " + json.dumps(row))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--case", default="brain-tumour-brats-0005")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "out", "benchmark_scale"))
    ap.add_argument("--sizes", default=",".join(name for name, _ in SIZES))
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    ap.add_argument("--make", nargs=3, help=argparse.SUPPRESS)
    ap.add_argument("--hugepages", action="store_true", help="run with malloc using transparent huge pages")
    args = ap.parse_args()
    if args.hugepages:
        report.use_huge_pages(sys.argv)
    if args.child:
        return child(args.child[0], args.child[1], args.child[2] == "once")
    if args.make:
        return make_image(args.make[0], args.make[1], int(args.make[2]) if args.make[2].isdigit() else float(args.make[2]))
    import featuremesh as fm
    folder = fm.case_dir(args.case)
    if folder is None:
        raise SystemExit("case %s not found (bundled Data/ or ../shared/data/cases)" % args.case)
    pvpython = shutil.which("pvpython") or sys.executable
    work = tempfile.mkdtemp()
    rows = []
    try:
        for name, factor in [(n, f) for n, f in SIZES if n in args.sizes.split(",")]:
            image = os.path.join(folder, "image.mha")
            if factor is not None:
                image = os.path.join(work, "image_%s.mha" % name.replace("^", ""))
                subprocess.run([pvpython, __file__, "--make", os.path.join(folder, "image.mha"), image, str(factor)], check=True)
            row = {"size": name}
            for mode in ("stages", "once"):
                run = subprocess.run([pvpython, __file__, "--child", folder, image, mode], capture_output=True, text=True)
                lines = [l for l in run.stdout.splitlines() if l.startswith("RESULT ")]
                if run.returncode != 0 or not lines:
                    print("%s: failed (%s)" % (name, run.stderr[-800:]))
                    break
                row.update(json.loads(lines[-1][7:]))
            if "at_once_s" not in row:
                continue
            row["total_s"] = sum(row[k] for k in ("nodes_s", "mesh_s", "smoothing_s", "cut_s"))
            row["us_per_voxel"] = 1e6 * row["total_s"] / row["voxels"]
            row["bytes_per_voxel"] = row["peak_gb"] * 1024.0 ** 3 / row["voxels"]
            rows.append(row)
            print(" | ".join("%s %s" % (k, ("%.3f" % v) if isinstance(v, float) else v) for k, v in row.items()), flush=True)
            if factor is not None:
                os.remove(image)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    keys = ["size", "voxels", "elements", "nodes_s", "mesh_s", "smoothing_s", "sweeps_s", "refinement_s", "slivers_s",
            "statistics_s", "cut_s", "total_s", "us_per_voxel",
            "nodes_peak_gb", "mesh_peak_gb", "smoothing_peak_gb", "peak_gb", "bytes_per_voxel", "at_once_s", "at_once_peak_gb"]
    machine = report.machine()
    write_table(args.out, rows, keys, "Machine: %s; %s, one run per size, each in its own process." % (machine, args.case))

if __name__ == "__main__":
    main()
