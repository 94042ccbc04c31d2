"""Several labels: the bundled abdomen CT (liver, spleen, two kidneys, stomach) from its seeds.csv
(x,y,z,label) straight from ParaView's CSV reader into both cuts; Dice floors per label and on the
mean (measured values - 0.02, docs/multilabel.md); every seed keeps its label; a seed edit
re-cuts the kept mesh; stage 6 smooths every interface with no inverted element; the FEM files read
back in meshio with a region per label named after it and a tag per pair of touching labels. The
two-channel BraTS tumour regions (shared data only) keep their mean floors."""
import os

import meshio

import fmtest as ft
from featuremesh import fem, metrics

np = ft.np
# Measured at the defaults (benchmark_multilabel.py) minus 0.02.
# Super-voxel 0.854 / 0.714 / 0.764 (0.817 / 0.716 / 0.763 with the element cut's histograms from
# the seed elements' voxels instead of those near the seeds).
FLOORS = {"abdomen-ct-totalseg": {"supervoxel": 0.834, "voxel": 0.851},
          "brain-tumour-regions-brats-0005": {"supervoxel": 0.694},
          "brain-tumour-regions-brats-0006": {"supervoxel": 0.744}}

cases = ft.fm.multilabel_cases()
ft.check("abdomen-ct-totalseg" in cases, "the abdomen case is bundled")
for name, folder in cases.items():
    case = ft.fm.MultiLabelCase(folder)
    truth = case.truth()
    k = int(truth.max())
    mesh = case.mesh()
    cut = case.super_voxel_cut(mesh)
    cut.UpdatePipeline()
    labels = ft.fm.labels(cut)
    dice = [ft.dice(labels == l, truth == l) for l in range(1, k + 1)]
    print(name, "super-voxel Dice per label", np.round(dice, 3), "mean %.3f" % np.mean(dice))
    ft.check(np.mean(dice) >= FLOORS[name]["supervoxel"], "%s: mean Dice %.3f >= %.3f" % (name, np.mean(dice), FLOORS[name]["supervoxel"]))
    image = ft.fetch(case.image)
    for x, y, z, label in case.seed_rows():
        ijk = [0.0, 0.0, 0.0]
        image.TransformPhysicalPointToContinuousIndex([x, y, z], ijk)
        i, j, kk = (int(np.floor(c + 0.5)) for c in ijk)
        dims = image.GetDimensions()
        ft.check(labels[(kk * dims[1] + j) * dims[0] + i] == label, "%s: the seed at %s keeps label %d" % (name, (x, y, z), label))
    field = ft.fetch(cut, 2).GetFieldData()
    ft.check(field.GetArray(ft.names.Labels).GetValue(0) == k + 1, "%s: %d labels" % (name, k + 1))
    ft.check(field.GetAbstractArray(ft.names.LabelNames).GetComponentName(1) == case.names[1], "%s: label 1 is named %s" % (name, case.names[1]))
    # The seeds' reach per label: R, the largest distance from one of its seeds' voxels to the nearest
    # background seed's voxel (0 for the background).
    at = {}
    for x, y, z, label in case.seed_rows():
        ijk = [0.0, 0.0, 0.0]
        image.TransformPhysicalPointToContinuousIndex([x, y, z], ijk)
        at.setdefault(label, []).append(np.floor(np.array(ijk) + 0.5) * image.GetSpacing())
    want = [0.0] + [max(np.linalg.norm(np.array(at[0]) - s, axis=1).min() for s in at[l]) for l in range(1, k + 1)]
    got = ft.v2n(field.GetArray(ft.names.SeedReachDistance))
    ft.check(len(got) == k + 1 and np.allclose(got, want, rtol=1e-9) and min(want[1:]) > 0,
             "%s: the seeds' reach R per label %s mm (%s from the seeds)" % (name, np.round(got, 2), np.round(want, 2)))
    if name != "abdomen-ct-totalseg":
        continue

    voxel = case.voxel_cut()
    voxel.UpdatePipeline()
    vdice = [ft.dice(ft.fm.labels(voxel, 0) == l, truth == l) for l in range(1, k + 1)]
    ft.check(np.mean(vdice) >= FLOORS[name]["voxel"], "%s: voxel cut mean Dice %.3f >= %.3f" % (name, np.mean(vdice), FLOORS[name]["voxel"]))
    # The stomach, the weakest organ: 0.757 measured (0.639 from the seed elements' samples).
    ft.check(min(dice) >= 0.737, "%s: every organ's Dice >= 0.737 (%.3f)" % (name, min(dice)))

    # On the local contrast (Intensity 1) the labelled cut runs too, every seed holds and it stays
    # an organ segmentation (mean Dice 0.776 measured; the values give 0.854).
    local = case.super_voxel_cut(mesh, Intensity=1)
    local.UpdatePipeline()
    llabels = ft.fm.labels(local)
    ldice = np.mean([ft.dice(llabels == l, truth == l) for l in range(1, k + 1)])
    ft.check(ldice >= 0.70, "%s: on the local contrast mean Dice %.3f >= 0.70" % (name, ldice))
    held = 0
    for x, y, z, label in case.seed_rows():
        ijk = [0.0, 0.0, 0.0]
        image.TransformPhysicalPointToContinuousIndex([x, y, z], ijk)
        i, j, kk = (int(np.floor(c + 0.5)) for c in ijk)
        held += llabels[(kk * dims[1] + j) * dims[0] + i] == label
    ft.check(held == len(case.seed_rows()), "%s: on the local contrast every seed keeps its label" % name)
    # A seed edit: one more liver seed; only the cut re-runs, and the seeds still hold.
    rows = case.seed_rows() + [(case.seed_rows()[0][0] + 6.0, case.seed_rows()[0][1], case.seed_rows()[0][2], 1)]
    path = os.path.join(ft.scratch("featuremesh-multilabel-"), "seeds.csv")
    with open(path, "w") as f:
        f.write("x,y,z,label\n" + "".join("%g,%g,%g,%d\n" % r for r in rows))
    cut.Seeds = ft.ps.CSVReader(FileName=[path])
    cut.UpdatePipeline()
    edited = ft.fm.labels(cut)
    ft.check(abs(np.mean([ft.dice(edited == l, truth == l) for l in range(1, k + 1)]) - np.mean(dice)) < 0.05,
             "%s: one added seed moves the mean Dice by less than 0.05" % name)

    # The voxel refinement keeps its domain across re-cuts (held voxels as hard nodes, its faces and
    # the expansion's rows of edges kept): seeds added where the result is wrong (the domain grows) and
    # the last one moved by a voxel and back (the band stays inside it) give what a fresh filter gives.
    from benchmark_multilabel import robot_seed
    dims = image.GetDimensions()
    shape, spacing = (dims[2], dims[1], dims[0]), np.asarray(image.GetSpacing())
    for step in range(5):
        if step % 2 == 0:
            kk, j, i, label = robot_seed(ft.fm.labels(cut), truth, shape, spacing)
            rows.append(image.GetPoint(image.ComputePointId([int(i), int(j), int(kk)])) + (label,))
        else:
            x, y, z, label = rows[-1]
            rows[-1] = (x + spacing[0] * (1 if step % 4 == 1 else -1), y, z, label)
        path = os.path.join(os.path.dirname(path), "seeds%d.csv" % step)
        with open(path, "w") as f:
            f.write("x,y,z,label\n" + "".join("%.17g,%.17g,%.17g,%d\n" % r for r in rows))
        cut.Seeds = ft.ps.CSVReader(FileName=[path])
        cut.UpdatePipeline()
        fresh = case.super_voxel_cut(mesh)
        fresh.Seeds = ft.ps.CSVReader(FileName=[path])
        fresh.UpdatePipeline()
        refined = ft.fetch(fresh, 0).GetFieldData().GetArray(ft.names.RelabelledVoxels).GetValue(0)
        ft.check(refined > 0 and np.array_equal(ft.fm.labels(cut), ft.fm.labels(fresh)),
                 "%s, edit %d: the kept refinement equals a fresh one (%d voxels relabelled)" % (name, step, refined))
        ft.Delete(fresh)

    # Stage 6 with six labels, and the FEM files.
    smooth = ft.ps.SegmentationSurfaceSmoothing(LabelledMesh=ft.ps.OutputPort(cut, 0))
    smooth.UpdatePipeline()
    grid = ft.fetch(smooth, 1)
    points, cells, cell_labels = fem.grid_arrays(grid)
    ft.check(len(np.unique(cell_labels)) == k + 1, "%s: the smoothed mesh keeps %d labels" % (name, k + 1))
    volume = fem.element_measures(points, cells)
    ft.check(volume.min() > 0, "%s: no inverted element after stage 6 (smallest volume %.3g)" % (name, volume.min()))
    dihedral = metrics.element_angles(points, cells).min(axis=1)
    before = metrics.element_angles(*fem.grid_arrays(ft.fetch(cut, 0))[:2]).min(axis=1)
    ft.check(dihedral.min() >= min(8.0, before.min()) - 1e-6,
             "%s: smallest dihedral %.2f >= min(8, before %.2f)" % (name, dihedral.min(), before.min()))
    region = fem.label_names(grid, cell_labels)
    ft.check([region[l] for l in range(k + 1)] == case.names, "%s: regions named %s" % (name, case.names))
    faces, tags = fem.boundary_faces(points, cells, cell_labels)
    pairs = sorted({(t - fem.PAIR_TAG0) // 256 * 1000 + (t - fem.PAIR_TAG0) % 256 for t in tags if t >= fem.PAIR_TAG0})
    ft.check(any(p // 1000 == 0 for p in pairs) and any(p // 1000 > 0 for p in pairs),
             "%s: interfaces with the background and between organs (%s)" % (name, pairs))
    # Each label's boundary (its cells' faces not shared by two of its cells: interfaces and box
    # faces) is closed: every edge lies on an even number of its faces.
    for l in range(1, k + 1):
        _, _, _, key = fem._faces(cells[cell_labels == l])
        unique, counts = np.unique(key, axis=0, return_counts=True)
        f = unique[counts == 1]
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [0, 2]]]), axis=1)
        _, counts = np.unique(edges, axis=0, return_counts=True)
        ft.check((counts % 2 == 0).all(), "%s: the boundary of %s is closed" % (name, region[l]))
    out = ft.scratch("featuremesh-multilabel-fem-")
    files = fem.write(grid, os.path.join(out, name))
    names = fem.tag_names(3, region)
    pair_names = sorted(names[t] for t in set(tags.tolist()) if t >= fem.PAIR_TAG0)
    for fmt, path in files.items():
        m = meshio.read(path)
        ft.check(len(m.cells_dict["tetra"]) == len(cells), "%s %s: %d tetrahedra read back" % (name, fmt, len(cells)))
        if fmt == "gmsh":
            ft.check(all(n in m.field_data for n in case.names), "gmsh: a physical group per label")
            ft.check(all(n in m.field_data for n in pair_names), "gmsh: a physical group per pair (%s)" % pair_names)
        if fmt == "abaqus":
            ft.check(all(n in m.cell_sets for n in case.names), "abaqus: an element set per label")
            ft.check(all(n.replace("|", "__") in m.point_sets for n in pair_names), "abaqus: a node set per pair")
        if fmt == "exodus":
            ft.check(all(n in m.point_sets for n in pair_names), "exodus: a node set per pair")
        if fmt == "medit":
            refs = np.concatenate([r for r in m.cell_data["medit:ref"]])
            ft.check(set(range(k + 1)) <= set(refs.tolist()), "medit: a ref per label")
ft.finish()
