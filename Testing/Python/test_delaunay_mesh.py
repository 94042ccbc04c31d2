"""Stage 2 on real data: exact tiling and statistics, Delaunay property, bad input."""
import numpy as np

import fmtest as ft

rng = np.random.default_rng(3)


def measures(P, C):
    a, b, c = P[C[:, 1]] - P[C[:, 0]], P[C[:, 2]] - P[C[:, 0]], None
    if C.shape[1] == 3:
        return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    c = P[C[:, 3]] - P[C[:, 0]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0


def circum(P, cell):
    X = P[cell]
    if len(cell) == 3:
        X = X[:, :2]
    A = 2 * (X[1:] - X[0])
    rhs = (X[1:] ** 2).sum(1) - (X[0] ** 2).sum()
    centre = np.linalg.solve(A, rhs)
    return centre, np.linalg.norm(X[0] - centre)


for case, backends in (("nuclei-dsb2018", [0]), ("liver-ct-totalseg", [0, 1])):
    d, image, truth = ft.open_case(case)
    nodes = ft.FeatureNodes(Input=image)
    im = ft.fetch(image)
    dims = im.GetDimensions()
    sp = np.array(im.GetSpacing())
    values = ft.array(im).astype(float).reshape(dims[::-1])
    node_pts = ft.v2n(ft.fetch(nodes).GetPoints().GetData())
    for backend in backends:
        tag = "%s/%s" % (case, ["TetGen" if dims[2] > 1 else "CGAL 2D", "CGAL"][backend])
        mesh = ft.DelaunayImageMesh(Nodes=nodes, Image=image, Backend=backend)
        mesh.UpdatePipeline()
        ug = ft.fetch(mesh)
        P = ft.v2n(ug.GetPoints().GetData())
        C = ft.v2n(ug.GetCells().GetConnectivityArray()).reshape(ug.GetNumberOfCells(), -1)
        pc = ft.array(ug, ft.names.PixelCount, cells=True)
        ft.check(pc.sum() == np.prod(dims), "%s: PixelCount sums to the %d voxels" % (tag, np.prod(dims)))
        m = measures(P, C)
        box = np.prod((np.array(dims) - 1)[: 2 if dims[2] == 1 else 3] * sp[: 2 if dims[2] == 1 else 3])
        ft.check(abs(m.sum() - box) <= 1e-9 * box, "%s: element measures sum to the box (rel. err %.1e)" % (tag, abs(m.sum() - box) / box))
        ft.check(m.min() > 0, "%s: no element of zero or negative measure (min %.3g)" % (tag, m.min()))
        ft.check(np.array_equal(P[: len(node_pts)], node_pts), "%s: every input node is a mesh point, in order" % tag)
        quality = ft.names.MinAngle if dims[2] == 1 else ft.names.MinDihedralAngle
        for name in (ft.names.MeanIntensity, ft.names.IntensityStdDev, ft.names.Interpolated, quality, ft.names.RadiusRatio):
            ft.check(ug.GetCellData().GetArray(name) is not None, "%s: cell array %s" % (tag, name))
        mean = ft.array(ug, ft.names.MeanIntensity, cells=True)
        checked = ft.brute_force_statistics(P, C, values, dims, sp, pc, mean, rng.choice(len(C), 400, replace=False))
        ft.check(checked >= 50, "%s: MeanIntensity and PixelCount match brute force on %d sampled elements" % (tag, checked))
        # Empty circumcircle / circumsphere on a sample (points on the sphere are allowed: lattice ties).
        bad = 0
        for e in rng.choice(len(C), 200, replace=False):
            centre, r = circum(P, C[e])
            dist = np.linalg.norm(P[:, : len(centre)] - centre, axis=1)
            bad += int((dist < r * (1 - 1e-9)).sum())
        ft.check(bad == 0, "%s: Delaunay property on 200 sampled elements" % tag)
        ft.check(ft.array(ug, quality, cells=True).min() > 0, "%s: positive minimum angle / dihedral" % tag)

# Bad input: each an error with empty output.
d, image, truth = ft.open_case("nuclei-dsb2018")


def mesh_cells(points):
    src = ft.PolyPointSource(Points=sum(points, []))
    mesh = ft.DelaunayImageMesh(Nodes=src, Image=image)
    mesh.UpdatePipeline()
    return ft.fetch(mesh).GetNumberOfCells()


ft.check(mesh_cells([[0, 0, 0], [511, 0, 0], [0, 511, 0], [511, 511, 0], [100, 100, 0]]) > 0, "five good nodes mesh")
ft.check(mesh_cells([[0, 0, 0], [5, 5, 0]]) == 0, "fewer than 3 nodes: error")
ft.check(mesh_cells([[0, 0, 0], [5, 5, 0], [9, 9, 0], [20, 20, 0]]) == 0, "collinear nodes: error")
ft.check(mesh_cells([[0, 0, 0], [5, 5, 0], [5, 5, 0], [9, 2, 0]]) == 0, "duplicate nodes: error")
ft.check(mesh_cells([[0, 0, 0], [5, 5, 0], [900, 2, 0], [9, 2, 0]]) == 0, "nodes outside the image: error")
ft.check(mesh_cells([[0, 0, 0], [5, 5, 3], [50, 2, 0], [9, 2, 0]]) == 0, "nodes off a 2D image's plane: error")
d3, image3, _ = ft.open_case("liver-ct-totalseg")
flat = ft.PolyPointSource(Points=[0, 0, 0, 30, 0, 0, 0, 30, 0, 30, 30, 0, 12, 9, 0])
m3 = ft.DelaunayImageMesh(Nodes=flat, Image=image3)
m3.UpdatePipeline()
ft.check(ft.fetch(m3).GetNumberOfCells() == 0, "coplanar nodes in 3D: error")

# Quality refinement (TetGen with the box as its domain) on the 3D cases: the requested minimum
# dihedral angle is reached, nodes are added, and every voxel still has exactly one element.
for case in ("liver-ct-totalseg", "brain-tumour-brats-0005"):
    if ft.fm.case_dir(case) is None:
        print("SKIP: %s not found" % case)
        continue
    c = ft.fm.Case(ft.fm.case_dir(case))
    nodes = c.feature_nodes()
    plain, refined = c.mesh(nodes), c.mesh(nodes, QualityRefinement=1, MinDihedralAngle=10, RadiusEdgeRatio=2)
    p, r = ft.fetch(plain), ft.fetch(refined)
    angle = ft.array(r, ft.names.MinDihedralAngle, cells=True).min()
    added = r.GetNumberOfPoints() - p.GetNumberOfPoints()
    ft.check(angle >= 9.99, "%s: quality refinement reaches a minimum dihedral angle of %.2f deg (plain mesh %.2f deg)" % (
        case, angle, ft.array(p, ft.names.MinDihedralAngle, cells=True).min()))
    ft.check(added > 0 and r.GetFieldData().GetArray(ft.names.AddedNodes).GetValue(0) == added, "%s: %d nodes added (%d -> %d)" % (
        case, added, p.GetNumberOfPoints(), r.GetNumberOfPoints()))
    ft.check(ft.array(r, ft.names.PixelCount, cells=True).sum() == ft.fetch(c.image).GetNumberOfPoints(),
             "%s: every voxel has one element after refinement" % case)
    types = ft.array(r, ft.names.NodeType)
    fixed = ft.array(r, ft.names.Fixed)
    ft.check((types[p.GetNumberOfPoints():] == 4).all() and (fixed[p.GetNumberOfPoints():] == 0).all(),
             "%s: added nodes are NodeType 4, not fixed" % case)
ft.finish("mesh")
