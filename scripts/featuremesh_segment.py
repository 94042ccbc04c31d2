"""FeatureMesh main job (pvpython / pvbatch): image + seeds -> [RSP edges ->] nodes -> mesh -> smoothed mesh -> super-voxel cut
-> smoothed segmentation surface and a labelled FEM mesh.

usage: pvpython featuremesh_segment.py IMAGE (--object-seeds CSV --background-seeds CSV | --seeds CSV [--labels CSV])
                                       [--truth LABELS] [--out DIR] [--plugin FeatureMesh.so]
                                       [--task object|class] [--lambda L] [--connectivity task|off|fill|seeded]
                                       [--intensity task|image|contrast] [--contrast-scale S] [--sigma S] [--bins B]
                                       [--no-smoothing] [--rsp] [--surface-method taubin|laplacian]
                                       [--surface-iterations N] [--unit mm]
--rsp runs RSP Edge Enhancement first and feeds its edge map to Feature Nodes (seed-aware nodes: fine
at the seeded object's boundary, coarse away from it; writes DIR/<name>_edge_confidence.vti too).
The cut's options default to the Super-Voxel Cut's own defaults (see its properties in ParaView).
Seeds: CSV files with columns x,y,z in world coordinates, or "x,y,z;x,y,z" on the command line; or
--seeds, one CSV with columns x,y,z,label (0 background, 1..k objects: k objects by alpha-expansion,
on every channel of the image; stages 1-3 run on its first channel) and --labels, a CSV with columns
label,name (the FEM regions and pair tags take the names). With a truth image of labels 0..k the
report gives Dice per label.
Writes DIR/<name>_mesh.vtu (the cut's labelled mesh), _boundary.vtp (the smoothed boundary),
_labels.vti, _fem.vtu (the labelled mesh with the smoothed interface) and the same mesh for FEM codes:
_fem.msh (Gmsh 2.2), _fem.mesh (Medit), _fem.inp (Abaqus), _fem.exo (Exodus II), with region and
boundary tags as scripts/featuremesh/fem.py lists them; _report.json (also printed), _view.png and
_quality.png (the quality histogram per label).
"""
import argparse
import json
import os
import time

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403
import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n
from vtkmodules.vtkIOXML import vtkXMLImageDataWriter, vtkXMLPolyDataWriter, vtkXMLUnstructuredGridWriter

import featuremesh as fm
from featuremesh import fem, metrics

CONNECTIVITY = {"task": "From Task", "off": "Off", "fill": "Fill Holes", "seeded": "Seeded Object"}
TASK = {"object": "Object", "class": "Class"}
INTENSITY = {"task": "From Task", "image": "Image", "contrast": "Local Contrast"}
SURFACE_METHOD = {"laplacian": 0, "taubin": 1}


def cells_of(grid):
    return v2n(grid.GetCells().GetConnectivityArray()).reshape(grid.GetNumberOfCells(), -1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("image")
    ap.add_argument("--object-seeds")
    ap.add_argument("--background-seeds")
    ap.add_argument("--seeds", help="labelled seeds: CSV with columns x,y,z,label (instead of the two seed files)")
    ap.add_argument("--labels", help="label names: CSV with columns label,name (with --seeds)")
    ap.add_argument("--truth")
    ap.add_argument("--out", default="out")
    ap.add_argument("--plugin")
    cut_options = ap.add_argument_group("Super-Voxel Cut (default: the filter's own defaults)")
    cut_options.add_argument("--task", choices=sorted(TASK),
                             help="object: the one object the object seeds lie in (a tumour, an organ; the default); "
                                  "class: every object like the seeded ones (all nuclei, all cells, all vessels)")
    cut_options.add_argument("--lambda", dest="lam", type=float, help="region-term weight (property Lambda)")
    cut_options.add_argument("--connectivity", choices=sorted(CONNECTIVITY),
                             help="off: the cut as it is; fill: fill background holes (several objects of a kind "
                                  "stay); seeded: one object, what the object seeds reach")
    cut_options.add_argument("--intensity", choices=sorted(INTENSITY),
                             help="what the cut reads: image: the image's values; contrast: their local contrast "
                                  "(shading drops out); task: contrast for --task class, image for object")
    cut_options.add_argument("--contrast-scale", type=float,
                             help="Gaussian scale (voxels) of the local contrast's neighbourhood (property ContrastScale)")
    cut_options.add_argument("--sigma", type=float, help="boundary-term sigma, 0 = automatic")
    cut_options.add_argument("--bins", type=int, help="seed histogram bins, 0 = automatic")
    ap.add_argument("--no-smoothing", action="store_true", help="cut the Delaunay mesh (skip Image Mesh Smoothing)")
    ap.add_argument("--rsp", action="store_true",
                    help="seed-aware nodes: RSP Edge Enhancement's edge map on Feature Nodes' Edge Map input")
    surface = ap.add_argument_group("Segmentation Surface Smoothing (default: the filter's own defaults)")
    surface.add_argument("--surface-method", choices=sorted(SURFACE_METHOD),
                         help="taubin (the default, 10 iterations; keeps the volume) or laplacian (the thesis "
                              "with --surface-iterations 3; shrinks)")
    surface.add_argument("--surface-iterations", type=int, help="smoothing iterations (property Iterations)")
    ap.add_argument("--unit", default="mm", help="the image spacing's unit, written where a format has a place for it "
                                                  "(MetaImage and NRRD do not record it; default mm)")
    args = ap.parse_args()
    if not args.seeds and not (args.object_seeds and args.background_seeds):
        ap.error("give --object-seeds and --background-seeds, or --seeds")
    fm.load_plugin(args.plugin, ns=globals())
    os.makedirs(args.out, exist_ok=True)
    stem = os.path.basename(args.image)
    stem = stem[: -len(".nii.gz")] if stem.lower().endswith(".nii.gz") else os.path.splitext(stem)[0]
    name = os.path.basename(os.path.dirname(os.path.abspath(args.image))) if stem == "image" else stem
    base = os.path.join(args.out, name)

    times = {}
    t = time.perf_counter()
    image = fm.open_image(args.image)
    image.UpdatePipeline()
    times["read"] = time.perf_counter() - t
    array = image.PointData.keys()[0]
    channels = image.PointData[array].GetNumberOfComponents()
    # Stages 1-3 see one channel; the cut sees them all.
    first = ExtractComponent(Input=image, InputArray=["POINTS", array], Component=0, OutputArrayName="Channel0") \
        if channels > 1 else image
    scalars = ["POINTS", "Channel0" if channels > 1 else array]
    if args.seeds:
        labelled_seeds = ps.CSVReader(FileName=[os.path.abspath(args.seeds)])
        so = sb = None
        names = fm.label_names_from_csv(args.labels) if args.labels else None
        if args.rsp:
            raise SystemExit("--rsp takes --object-seeds and --background-seeds")
    else:
        so, sb = fm.seeds(args.object_seeds), fm.seeds(args.background_seeds)
        so.UpdatePipeline()
        sb.UpdatePipeline()
    rsp = RSPEdgeEnhancement(Input=image, ObjectSeeds=so, BackgroundSeeds=sb) if args.rsp else None
    nodes = FeatureNodes(Input=first, Scalars=scalars, EdgeMap=rsp) if args.rsp else FeatureNodes(Input=first, Scalars=scalars)
    delaunay = DelaunayImageMesh(Nodes=nodes, Image=first, Scalars=scalars)
    mesh = delaunay if args.no_smoothing else ImageMeshSmoothing(Mesh=delaunay, Image=first, Scalars=scalars)
    options = {name: value for name, value in (("Lambda", args.lam), ("Sigma", args.sigma), ("Bins", args.bins),
               ("Connectivity", CONNECTIVITY.get(args.connectivity)), ("Task", TASK.get(args.task)),
               ("Intensity", INTENSITY.get(args.intensity)), ("ContrastScale", args.contrast_scale))
               if value is not None}
    if args.seeds:
        if names:
            options["LabelNames"] = ";".join(names)
        cut = SuperVoxelCut(Mesh=mesh, Seeds=labelled_seeds, Image=image, Scalars=["POINTS", array], **options)
    else:
        cut = SuperVoxelCut(Mesh=mesh, ObjectSeeds=so, BackgroundSeeds=sb, Image=image, **options)
    stages = ([("rsp_edge_enhancement", rsp)] if args.rsp else []) + [("feature_nodes", nodes), ("delaunay_image_mesh", delaunay)]
    stages += [] if args.no_smoothing else [("image_mesh_smoothing", mesh)]
    surface_options = {name: value for name, value in (("Method", SURFACE_METHOD.get(args.surface_method)),
                                                       ("Iterations", args.surface_iterations)) if value is not None}
    smooth = SegmentationSurfaceSmoothing(LabelledMesh=ps.OutputPort(cut, 0), **surface_options)
    for stage, proxy in stages + [("super_voxel_cut", cut), ("segmentation_surface_smoothing", smooth)]:
        t = time.perf_counter()
        proxy.UpdatePipeline()
        times[stage] = time.perf_counter() - t
    labelled, labels = sm.Fetch(cut, idx=0), sm.Fetch(cut, idx=2)
    boundary, fem_mesh = sm.Fetch(smooth, idx=0), sm.Fetch(smooth, idx=1)
    if labelled.GetNumberOfCells() == 0 or fem_mesh.GetNumberOfCells() == 0:
        raise SystemExit("the pipeline failed; see the errors above")
    for writer, data, suffix in ((vtkXMLUnstructuredGridWriter(), labelled, "_mesh.vtu"),
                                 (vtkXMLPolyDataWriter(), boundary, "_boundary.vtp"),
                                 (vtkXMLImageDataWriter(), labels, "_labels.vti"),
                                 (vtkXMLUnstructuredGridWriter(), fem_mesh, "_fem.vtu")):
        writer.SetInputData(data)
        writer.SetFileName(base + suffix)
        writer.Write()
    if args.rsp:
        writer = vtkXMLImageDataWriter()
        writer.SetInputData(sm.Fetch(rsp))
        writer.SetFileName(base + "_edge_confidence.vti")
        writer.Write()
    t = time.perf_counter()
    fem_files = fem.write(fem_mesh, base + "_fem", unit=args.unit)
    times["fem_export"] = time.perf_counter() - t
    fd = labelled.GetFieldData()
    sfd = boundary.GetFieldData()
    smoothing = {sfd.GetArrayName(i): sfd.GetArray(i).GetValue(0) for i in range(sfd.GetNumberOfArrays())
                 if sfd.GetArray(i).GetNumberOfTuples() == 1}
    field = {fd.GetArrayName(i): fd.GetArray(i).GetValue(0) for i in range(fd.GetNumberOfArrays()) if fd.GetArray(i) is not None}
    quality = v2n(labelled.GetCellData().GetArray(fm.names.MinAngle) or labelled.GetCellData().GetArray(fm.names.MinDihedralAngle))
    raw = sm.Fetch(delaunay)
    angles = {"delaunay": metrics.mesh_quality(v2n(raw.GetPoints().GetData()), cells_of(raw)),
              "final": metrics.mesh_quality(v2n(labelled.GetPoints().GetData()), cells_of(labelled))}
    report = {"image": os.path.abspath(args.image), "seconds": times, "total_seconds": sum(v for k, v in times.items() if k != "read"),
              "nodes": labelled.GetNumberOfPoints(), "elements": labelled.GetNumberOfCells(),
              "min_quality_degrees": float(quality.min()), "median_quality_degrees": float(sorted(quality)[len(quality) // 2]),
              # Minimum, 1st percentile of the element minima, maximum: angles (2D) or dihedral angles (3D).
              "angles_degrees": angles, "smoothing": not args.no_smoothing, "rsp": args.rsp,
              "added_nodes": int(field.get("AddedNodes", 0)) if not args.no_smoothing else 0,
              "object_elements": int((v2n(labelled.GetCellData().GetArray(fm.names.Label)) > 0).sum()),
              "task": cut.GetProperty("Task").GetData(), "lambda": float(cut.Lambda),
              "connectivity": cut.GetProperty("Connectivity").GetData(),
              "intensity": cut.GetProperty("Intensity").GetData(), "contrast_scale": float(cut.ContrastScale),
              "sigma": field.get("Sigma"), "flow": field.get("Flow"),
              "labels": int(field.get(fm.names.Labels, 2)), "expansion_moves": field.get(fm.names.ExpansionMoves),
              "energy": field.get("Energy"),
              "object_components": int(field.get("ObjectComponents", 0)),
              # World units (the image spacing's unit, squared in 2D, cubed in 3D), largest first.
              "object_component_volumes": [float(v) for v in v2n(fd.GetArray(fm.names.ObjectComponentVolumes))]
              if fd.GetArray(fm.names.ObjectComponentVolumes) else None,
              "surface_smoothing": {"method": smooth.GetProperty("Method").GetData(), "iterations": int(smooth.Iterations),
                                    "boundary_nodes": int(smoothing["BoundaryNodes"]), "short_nodes": int(smoothing["ShortNodes"]),
                                    "pinched_nodes": int(smoothing["PinchedNodes"]),
                                    "max_shortfall": smoothing["MaxShortfall"],
                                    # Object area (2D) / volume (3D) after / before - 1.
                                    "measure_change": smoothing["MeasureChange"]},
              # The labelled mesh with the smoothed interface: per label its elements, measure (world units),
              # face-connected components and quality histogram; the files and their unit.
              "fem": dict(fem.report(fem_mesh), unit=args.unit, files=fem_files)}
    if args.truth:
        truth = fm.open_image(args.truth)
        T = v2n(sm.Fetch(truth).GetPointData().GetScalars())
        L = v2n(labels.GetPointData().GetScalars())
        if T.max() > 1:
            region = fem.label_names(fem_mesh, L)
            report["dice_per_label"] = {region.get(k, "label_%d" % k): float(fm.dice(L == k, T == k))
                                        for k in range(1, int(T.max()) + 1)}
            report["dice"] = float(sum(report["dice_per_label"].values()) / len(report["dice_per_label"]))
        else:
            report["dice"] = float(fm.dice(L.astype(bool), T.astype(bool)))
    with open(base + "_report.json", "w") as f:
        json.dump(report, f, indent=2)
    quality_picture(report["fem"], "dihedral" if labels.GetDimensions()[2] > 1 else "element", base + "_quality.png")

    view = ps.CreateRenderView()
    view.ViewSize = [800, 800]
    view.OrientationAxesVisibility = 0
    dims = labels.GetDimensions()
    if dims[2] == 1:
        d = ps.Show(image, view)
        d.Representation = "Slice"
        ps.ColorBy(d, ("POINTS", image.PointData.keys()[0]))
        d.RescaleTransferFunctionToDataRange(False, True)
        ps.GetColorTransferFunction(image.PointData.keys()[0]).ApplyPreset("Grayscale", True)
        b = ps.Show(ps.OutputPort(smooth, 0), view)
        b.ColorArrayName = ['POINTS', '']
        b.AmbientColor = b.DiffuseColor = [1.0, 0.2, 0.2]
        b.LineWidth = 2
        b.Position = [0, 0, 1]
    elif int(field.get(fm.names.Labels, 2)) > 2:
        # Several objects: each label's elements in its own colour, with a categorical legend.
        objects = ps.Threshold(Input=ps.OutputPort(smooth, 1), Scalars=["CELLS", fm.names.Label], LowerThreshold=1,
                               UpperThreshold=255)
        b = ps.Show(objects, view)
        ps.ColorBy(b, ("CELLS", fm.names.Label))
        lut = ps.GetColorTransferFunction(fm.names.Label)
        region = fem.label_names(fem_mesh, v2n(fem_mesh.GetCellData().GetArray(fm.names.Label)))
        lut.InterpretValuesAsCategories = 1
        lut.Annotations = [str(v) for k in sorted(region) if k > 0 for v in (k, region[k])]
        lut.ApplyPreset("Brewer Qualitative Set1", True)
        b.SetScalarBarVisibility(view, True)
        view.CameraPosition = [1, -2, 1.2]
        view.CameraViewUp = [0, 0, 1]
    else:
        b = ps.Show(ps.OutputPort(smooth, 0), view)
        b.ColorArrayName = ['POINTS', '']
        b.DiffuseColor = [0.85, 0.5, 0.4]
        view.CameraPosition = [1, -2, 1.2]
        view.CameraViewUp = [0, 0, 1]
    view.ResetCamera()
    ps.SaveScreenshot(base + "_view.png", view)
    for suffix in ("_mesh.vtu", "_boundary.vtp", "_labels.vti", "_fem.vtu", "_report.json", "_view.png", "_quality.png"):
        print("wrote", base + suffix)
    print("wrote", ", ".join(fem_files.values()))
    volumes = report["object_component_volumes"]
    print("stage seconds:", ", ".join("%s %.3f" % kv for kv in times.items()), "| nodes %d, elements %d%s" % (
        report["nodes"], report["elements"], ", Dice %.3f" % report["dice"] if "dice" in report else ""))
    print("mesh quality (%s angles, deg): Delaunay min %.2f / 1st pct %.2f / max %.2f -> %s min %.2f / 1st pct %.2f / max %.2f" % (
        "dihedral" if dims[2] > 1 else "element", angles["delaunay"]["min"], angles["delaunay"]["p1"], angles["delaunay"]["max"],
        "Delaunay" if args.no_smoothing else "smoothed", angles["final"]["min"], angles["final"]["p1"], angles["final"]["max"]))
    if volumes is not None:
        print("object: %d component(s), volumes %s%s" % (len(volumes), ", ".join("%.4g" % v for v in volumes[:5]),
                                                        ", ..." if len(volumes) > 5 else ""))
    if "dice_per_label" in report:
        print("Dice per label:", ", ".join("%s %.3f" % kv for kv in report["dice_per_label"].items()))
    ss = report["surface_smoothing"]
    print("surface smoothing (%s, %d iterations): object %s %+.2f %%, %d of %d boundary nodes short of their smoothed position"
          % (ss["method"], ss["iterations"], "volume" if dims[2] > 1 else "area", 100 * ss["measure_change"],
             ss["short_nodes"], ss["boundary_nodes"]))
    for name, entry in report["fem"]["labels"].items():
        print("  %-10s %7d elements, %s %.6g %s^%d, %d component(s), smallest %s angle %.2f deg" % (
            name, entry["elements"], "volume" if dims[2] > 1 else "area", entry["measure"], args.unit,
            3 if dims[2] > 1 else 2, entry["components"], "dihedral" if dims[2] > 1 else "element", entry["min_quality_degrees"]))


def quality_picture(report, kind, path):
    """Bar chart of the quality histogram of each label (the report's bins)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    bins = report["histogram_bins_degrees"]
    fig, ax = plt.subplots(figsize=(7, 3.5), dpi=100)
    width = (bins[1] - bins[0]) / (len(report["labels"]) + 1)
    for k, (name, entry) in enumerate(report["labels"].items()):
        ax.bar([b + (k + 0.5) * width for b in bins[:-1]], entry["quality_histogram"], width, label=name)
    ax.set_yscale("log")
    ax.set_xlim(0, 90 if kind == "dihedral" else 60)
    ax.set_xlabel("smallest %s angle of the element (degrees)" % kind)
    ax.set_ylabel("elements")
    ax.set_title("Labelled FEM mesh: element quality per label")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


if __name__ == "__main__":
    main()
