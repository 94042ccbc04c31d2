"""Digests of every stage's output on every case (pvpython): the check behind "same results".

usage: pvpython scripts/digest.py [--cases a,b] [--out FILE] [--cut Lambda=1,Connectivity=0]
                                 [--surface Method=0,Iterations=3]
For each case (bundled Data/ and ../shared/data/cases) prints one line per output: the SHA-256 of
the node points and arrays, of the mesh (points, cells, every cell array by value) and of its
voxel -> element map, of the smoothed mesh (stage 3 at its defaults, default backend) and its map, of the
super-voxel labels (cells and label image), of Segmentation Surface Smoothing's output (the labelled
mesh's points and the boundary's faces), of the voxel cut's labels and of RSP Edge Enhancement's
outputs with the seed-aware nodes made from them (one line, last per case, so older digests compare line for line), at the default
properties (--cut overrides properties of both cuts, --surface of stage 6, e.g. the defaults of an older commit); 3D cases
also with the CGAL backend. Without --cases, the multi-label cases follow (labels, then two kept
re-cuts, each after a seed added where the result is most wrong). Compare two runs with diff.
"""
import argparse
import hashlib

import featuremesh as fm

# Cell arrays by value, in a fixed order; the quality array was once called Quality.
N = fm.names
CELL_ARRAYS = (N.PixelCount, N.MeanIntensity, N.IntensityStdDev, N.Interpolated, (N.MinAngle, N.MinDihedralAngle, "Quality"),
               N.RadiusRatio)


def sha(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        h.update(fm.np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


def ids(array):
    """Point ids as int64, whatever the cell array stores them in (stages 2 and 3 write 32-bit ids)."""
    return array.astype(fm.np.int64)


def cell_array(data, names):
    for n in (names if isinstance(names, tuple) else (names,)):
        a = data.GetCellData().GetArray(n)
        if a is not None:
            return fm.v2n(a)
    raise KeyError(names)


# Properties the Super-Voxel Cut has and the Voxel Cut has not: --cut passes them to the first only.
SUPER_VOXEL_ONLY = ("VoxelRefinement", "ScaleByContact", "VoxelRegionTerm", "SampleSeedElements", "SeedElementRadius",
                    "SuperVoxelIds")


def owners(proxy):
    """The voxel -> element map a mesh proxy keeps (fm.owner_map), or "none"."""
    a = fm.owner_map(proxy)
    return sha(fm.v2n(a)) if a is not None else "none"


def multilabel_lines(cut_properties):
    """Each multi-label case's super-voxel labels (cells and label image), then after each of two
    seeds added as benchmark_multilabel.py's robot user adds them (the kept re-cut)."""
    import os
    import tempfile
    import paraview.simple as ps
    from benchmark_multilabel import robot_seed, write_seeds
    lines = []
    for name, folder in fm.multilabel_cases().items():
        case = fm.MultiLabelCase(folder)
        image = fm.fetch(case.image)
        dims = image.GetDimensions()
        shape, spacing = (dims[2], dims[1], dims[0]), fm.np.asarray(image.GetSpacing())
        truth, rows = case.truth(), case.seed_rows()
        cut = case.super_voxel_cut(case.mesh(), **cut_properties)
        with tempfile.TemporaryDirectory() as tmp:
            for edit in range(3):
                if edit:
                    k, j, i, label = robot_seed(fm.labels(cut), truth, shape, spacing)
                    rows = list(rows) + [image.GetPoint(image.ComputePointId([i, j, k])) + (label,)]
                    path = os.path.join(tmp, "seeds%d.csv" % edit)
                    write_seeds(path, rows)
                    cut.Seeds = ps.CSVReader(FileName=[path])
                cut.UpdatePipeline()
                lines.append("%s multilabel %s %s" % (name, "labels" if edit == 0 else "recut%d" % edit,
                                                      sha(fm.v2n(fm.fetch(cut, 0).GetCellData().GetArray(N.Label)),
                                                          fm.v2n(fm.fetch(cut, 2).GetPointData().GetScalars()))))
                print(lines[-1], flush=True)
    return lines


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", default="")
    ap.add_argument("--out")
    ap.add_argument("--cut", default="", help="cut properties, e.g. Lambda=1,Connectivity=0")
    ap.add_argument("--surface", default="", help="Segmentation Surface Smoothing properties, e.g. Method=0,Iterations=3")
    args = ap.parse_args()
    cut_properties, surface_properties = fm.parse_properties(args.cut), fm.parse_properties(args.surface)
    fm.load_plugin()
    lines = []
    for name, d in fm.cases(args.cases).items():
        case = fm.Case(d)
        nodes = case.feature_nodes()
        n = fm.fetch(nodes)
        lines.append("%s nodes %s" % (name, sha(fm.v2n(n.GetPoints().GetData()),
                                               *[fm.v2n(n.GetPointData().GetArray(a)) for a in (N.NodeType, N.Fixed, N.SampleRadius)])))
        for backend in ([0, 1] if case.is3d else [0]):
            mesh = case.mesh(nodes, Backend=backend)
            m = fm.fetch(mesh)
            tag = "%s/%s" % (name, "CGAL" if backend else "default")
            lines.append("%s mesh %s" % (tag, sha(fm.v2n(m.GetPoints().GetData()), ids(fm.v2n(m.GetCells().GetConnectivityArray())),
                                                  *[cell_array(m, a) for a in CELL_ARRAYS])))
            lines.append("%s mesh owners %s" % (tag, owners(mesh)))
            cut = case.super_voxel_cut(mesh, **cut_properties)
            lines.append("%s labels %s" % (tag, sha(fm.v2n(fm.fetch(cut, 0).GetCellData().GetArray(N.Label)),
                                                    fm.v2n(fm.fetch(cut, 2).GetPointData().GetScalars()))))
            surface = case.surface_smoothing(cut, **surface_properties)
            f0, f1 = fm.fetch(surface, 0), fm.fetch(surface, 1)
            faces = f0.GetPolys() if f0.GetNumberOfPolys() else f0.GetLines()
            lines.append("%s surface %s" % (tag, sha(fm.v2n(f1.GetPoints().GetData()), ids(fm.v2n(faces.GetConnectivityArray())))))
            if backend == 0:
                smoothed = case.smoothing(mesh)
                s = fm.fetch(smoothed)
                lines.append("%s smoothed %s" % (tag, sha(fm.v2n(s.GetPoints().GetData()), ids(fm.v2n(s.GetCells().GetConnectivityArray())),
                                                          *[cell_array(s, a) for a in CELL_ARRAYS])))
                lines.append("%s smoothed owners %s" % (tag, owners(smoothed)))
        voxel_properties = {k: v for k, v in cut_properties.items() if k not in SUPER_VOXEL_ONLY}
        lines.append("%s voxelcut %s" % (name, sha(fm.v2n(fm.fetch(case.voxel_cut(**voxel_properties)).GetPointData().GetScalars()))))
        rsp = case.rsp()
        r, contour = fm.fetch(rsp, 0), fm.fetch(rsp, 1)
        seeded = fm.fetch(case.feature_nodes(edges=rsp))
        lines.append("%s rsp %s" % (name, sha(*[fm.v2n(r.GetPointData().GetArray(a)) for a in (N.EdgeConfidence, N.EdgeMap)],
                                             fm.v2n(contour.GetPoints().GetData()) if contour.GetPoints() else [],
                                             fm.v2n(seeded.GetPoints().GetData()))))
        print(lines[-1], flush=True)
    if not args.cases:
        lines += multilabel_lines(cut_properties)
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
