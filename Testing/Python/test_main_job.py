"""The main job's script on the bundled nuclei case with cut options: it writes every file, and its
report gives the options used, Dice, object components whose areas sum to the label image's, and the
mesh quality before and after smoothing (stage 3 runs by default). On both bundled cases the FEM files
read back in meshio with the .vtu's element count, per-label element counts and tagged boundary
faces, and the report's per-label measures, components and quality histograms match the mesh."""
import json
import os
import shutil
import subprocess

import fmtest as ft

d = ft.case_dir("nuclei-dsb2018")
out = ft.scratch()
script = os.path.join(ft.fm.ROOT, "scripts", "featuremesh_segment.py")
run = subprocess.run([shutil.which("pvpython"), script, os.path.join(d, "image.mha"),
                      "--object-seeds", os.path.join(d, "seeds_object.csv"),
                      "--background-seeds", os.path.join(d, "seeds_background.csv"),
                      "--truth", os.path.join(d, "truth.mha"), "--out", out,
                      "--lambda", "0.5", "--connectivity", "seeded"], capture_output=True, text=True)
ft.check(run.returncode == 0, "the script exits 0 (stderr: %s)" % run.stderr[-800:])
base = os.path.join(out, "nuclei-dsb2018")
for suffix in ("_mesh.vtu", "_boundary.vtp", "_labels.vti", "_fem.vtu", "_report.json", "_view.png", "_quality.png",
               "_fem.msh", "_fem.mesh", "_fem.inp", "_fem.exo"):
    ft.check(os.path.isfile(base + suffix), "wrote %s" % suffix)
report = json.load(open(base + "_report.json")) if os.path.isfile(base + "_report.json") else {}
ft.check(report.get("lambda") == 0.5 and report.get("connectivity") == "Seeded Object",
         "the report gives the options used (%s, %s)" % (report.get("lambda"), report.get("connectivity")))
labels = ft.array(ft.fetch(ft.ps.OpenDataFile(base + "_labels.vti"))) if os.path.isfile(base + "_labels.vti") else ft.np.zeros(0)
volumes = report.get("object_component_volumes", [])
ft.check(1 <= report.get("object_components", 0) <= 5 and len(volumes) == report.get("object_components"),
         "seeded object: between 1 and 5 components (5 object seeds), got %s" % report.get("object_components"))
ft.check(abs(sum(volumes) - labels.sum()) < 1e-6, "component areas sum to the label image's object area")
ft.check(0.0 < report.get("dice", 0) <= 1.0, "Dice reported")
angles = report.get("angles_degrees", {})
ft.check(report.get("smoothing") is True and "image_mesh_smoothing" in report.get("seconds", {}),
         "stages 1 -> 2 -> 3 -> 4 ran (smoothing timed)")
ft.check(angles.get("final", {}).get("min", 0) > angles.get("delaunay", {}).get("min", 90),
         "quality before / after in the report: min angle %s -> %s" % (angles.get("delaunay", {}).get("min"), angles.get("final", {}).get("min")))
ft.check("mesh quality" in run.stdout and "smoothed min" in run.stdout, "the script prints quality before / after")

# --rsp: RSP Edge Enhancement feeds Feature Nodes, on the liver (3D).
d = ft.case_dir("liver-ct-totalseg")
run = subprocess.run([shutil.which("pvpython"), script, os.path.join(d, "image.mha"),
                      "--object-seeds", os.path.join(d, "seeds_object.csv"),
                      "--background-seeds", os.path.join(d, "seeds_background.csv"),
                      "--truth", os.path.join(d, "truth.mha"), "--out", out, "--rsp"], capture_output=True, text=True)
ft.check(run.returncode == 0, "--rsp: the script exits 0 (stderr: %s)" % run.stderr[-800:])
base = os.path.join(out, "liver-ct-totalseg")
ft.check(os.path.isfile(base + "_edge_confidence.vti"), "--rsp: wrote the edge-confidence image")
report = json.load(open(base + "_report.json")) if os.path.isfile(base + "_report.json") else {}
ft.check(report.get("rsp") is True and "rsp_edge_enhancement" in report.get("seconds", {}),
         "--rsp: the report says RSP ran first (timed)")
ft.check(report.get("dice", 0) > 0.8, "--rsp: liver Dice %s > 0.8" % report.get("dice"))


def check_fem(base, is3d):
    """The FEM files against the _fem.vtu they were written from."""
    import meshio
    import netCDF4
    from featuremesh import fem
    name = os.path.basename(base)
    grid = ft.fetch(ft.ps.XMLUnstructuredGridReader(FileName=[base + "_fem.vtu"]))
    P, C, L = fem.grid_arrays(grid)
    F, T = fem.boundary_faces(P, C, L)
    volume, face = ("tetra", "triangle") if is3d else ("triangle", "line")
    per_label = {int(k): int((L == k).sum()) for k in ft.np.unique(L)}
    per_tag = {int(t): int((T == t).sum()) for t in ft.np.unique(T)}
    ft.check(set(per_tag) == {fem.INTERFACE_TAG} | {fem.BOX_TAG0 + s for s in range(6 if is3d else 4)},
             "%s: interface and every box side tagged (%s)" % (name, per_tag))
    # The interface plus the object's box faces are the smoothed boundary's faces.
    owner_object_box = sum(1 for f in F[T != fem.INTERFACE_TAG]
                           if L[ft.np.flatnonzero((ft.np.isin(C, f).sum(1) == len(f)))[0]] == 1)
    surface = ft.fetch(ft.ps.XMLPolyDataReader(FileName=[base + "_boundary.vtp"]))
    segments = surface.GetNumberOfCells() if is3d else int(sum(surface.GetCell(i).GetNumberOfPoints() - 1
                                                                  for i in range(surface.GetNumberOfCells())))
    ft.check(per_tag[fem.INTERFACE_TAG] + owner_object_box == segments,
             "%s: interface + object box faces = the smoothed boundary's %d faces" % (name, segments))
    for fmt in ("gmsh", "medit"):
        m = meshio.read(base + "_fem" + fem.FORMATS[fmt])
        key = "gmsh:physical" if fmt == "gmsh" else "medit:ref"
        tags = {}
        for block, data in zip(m.cells, m.cell_data[key]):
            for t, n in zip(*ft.np.unique(data, return_counts=True)):
                tags[(block.type, int(t))] = tags.get((block.type, int(t)), 0) + int(n)
        shift = 1 if fmt == "gmsh" else 0
        ft.check(sum(n for (k, _), n in tags.items() if k == volume) == len(C) and
                 all(tags.get((volume, k + shift)) == n for k, n in per_label.items()),
                 "%s %s: %d elements, per label %s" % (name, fmt, len(C), per_label))
        ft.check(all(tags.get((face, t)) == n for t, n in per_tag.items()), "%s %s: boundary faces per tag %s" % (name, fmt, per_tag))
        if fmt == "gmsh":
            ft.check(m.field_data.get("object", [0])[0] == 2 and m.field_data.get("interface", [0])[0] == fem.INTERFACE_TAG,
                     "%s gmsh: named physical groups" % name)
    nodes = {fem.tag_names(3 if is3d else 2)[t]: len(ft.np.unique(F[T == t])) for t in per_tag}
    for fmt in ("abaqus", "exodus"):
        m = meshio.read(base + "_fem" + fem.FORMATS[fmt])
        ft.check(sum(len(c.data) for c in m.cells if c.type == volume) == len(C), "%s %s: %d elements" % (name, fmt, len(C)))
        sizes = sorted(len(c.data) for c in m.cells if c.type == volume)
        ft.check(sizes == sorted(per_label.values()), "%s %s: one element set / block per label %s" % (name, fmt, sizes))
        ft.check({k: len(v) for k, v in m.point_sets.items()} == nodes, "%s %s: node sets %s" % (name, fmt, nodes))
        if fmt == "abaqus":
            ft.check({k: sum(len(x) for x in v) for k, v in m.cell_sets.items()} ==
                     {fem.REGION_NAMES[k]: n for k, n in per_label.items()}, "%s abaqus: element sets per label" % name)
    with netCDF4.Dataset(base + "_fem.exo") as root:
        info = [b"".join(r).decode() for r in root["info_records"][:]]
    ft.check(any("length unit: mm" in line for line in info), "%s exodus: the unit in its info records" % name)
    report = json.load(open(base + "_report.json"))
    measures = ft.np.abs(fem.element_measures(P, C))
    for k, n in per_label.items():
        entry = report["fem"]["labels"][fem.REGION_NAMES[k]]
        ft.check(entry["elements"] == n and sum(entry["quality_histogram"]) == n and
                 abs(entry["measure"] - measures[L == k].sum()) <= 1e-9 * measures.sum(),
                 "%s report: %s elements, measure and histogram" % (name, fem.REGION_NAMES[k]))
        ft.check(entry["components"] >= 1, "%s report: %s components %d" % (name, fem.REGION_NAMES[k], entry["components"]))
    ft.check(report["fem"]["labels"]["object"]["components"] == report["object_components"] or not is3d,
             "%s report: the FEM mesh's object components are the cut's (%d)" % (name, report["object_components"]))


check_fem(os.path.join(out, "nuclei-dsb2018"), False)
check_fem(os.path.join(out, "liver-ct-totalseg"), True)

# Labelled seeds: the abdomen's five organs from one CSV (x,y,z,label) and their names.
d = os.path.join(ft.fm.DATA, "multilabel", "abdomen-ct-totalseg")
run = subprocess.run([shutil.which("pvpython"), script, os.path.join(d, "image.mha"), "--seeds", os.path.join(d, "seeds.csv"),
                      "--labels", os.path.join(d, "labels.csv"), "--truth", os.path.join(d, "truth.mha"), "--out", out],
                     capture_output=True, text=True)
ft.check(run.returncode == 0, "--seeds: the script exits 0 (stderr: %s)" % run.stderr[-800:])
base = os.path.join(out, "abdomen-ct-totalseg")
report = json.load(open(base + "_report.json")) if os.path.isfile(base + "_report.json") else {}
names = ["liver", "spleen", "kidney_right", "kidney_left", "stomach"]
ft.check(list(report.get("dice_per_label", {})) == names and report.get("labels") == 6,
         "--seeds: Dice per named label (%s)" % report.get("dice_per_label"))
ft.check(list(report.get("fem", {}).get("labels", {})) == ["background"] + names, "--seeds: the FEM report per named label")
ft.check(all(os.path.isfile(base + "_fem" + s) for s in (".msh", ".mesh", ".inp", ".exo")), "--seeds: the four FEM files")
ft.finish("main-job")
