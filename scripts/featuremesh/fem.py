"""FEM export of a labelled mesh (Segmentation Surface Smoothing's output 1, or the Super-Voxel Cut's
output 0) through meshio: Gmsh, Medit, Abaqus and Exodus II, with one tag table for all of them.

Tags (the one source of truth; README "FEM export" and docs/surface.md list them):
- regions: label L is Gmsh physical group L + 1 (Gmsh reserves 0) named after the label (the grid's
  LabelNames field data, else REGION_NAMES, else label_L); Medit ref L on the elements; Abaqus element
  set and Exodus element block of the same name.
- boundary faces (triangles in 3D, edges in 2D): with labels 0 and 1 only, the interface is
  INTERFACE_TAG; with several object labels, each pair of touching labels a < b is PAIR_TAG0 + 256 a + b
  named "name_a|name_b" (Abaqus: "name_a__name_b", as its set names take letters, digits and
  underscores). The image box's sides are BOX_TAG0 + side (xmin, xmax, ymin, ymax[, zmin, zmax]).
  Gmsh physical groups and Medit refs on the faces, Abaqus and Exodus node sets of the same names.
"""
import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

from . import names as contract

REGION_NAMES = {0: "background", 1: "object"}
INTERFACE_TAG = 10
INTERFACE_NAME = "interface"
BOX_TAG0 = 11
BOX_SIDES = ["box_xmin", "box_xmax", "box_ymin", "box_ymax", "box_zmin", "box_zmax"]
PAIR_TAG0 = 1000
FORMATS = {"gmsh": ".msh", "medit": ".mesh", "abaqus": ".inp", "exodus": ".exo"}


def grid_arrays(grid):
    """(points (n, 3), cells (m, vpc), labels (m,)) of a triangle / tetrahedron vtkUnstructuredGrid."""
    points = v2n(grid.GetPoints().GetData()).astype(float)
    cells = v2n(grid.GetCells().GetConnectivityArray()).reshape(grid.GetNumberOfCells(), -1).astype(np.int64)
    labels = v2n(grid.GetCellData().GetArray(contract.Label)).astype(np.int64)
    return points, cells, labels


def _faces(cells):
    """Every local face of every cell: (cell, local face f, vertex ids without vertex f, sorted key)."""
    m, vpc = cells.shape
    local = np.array([[j for j in range(vpc) if j != f] for f in range(vpc)])
    ids = cells[:, local].reshape(m * vpc, vpc - 1)
    owner = np.repeat(np.arange(m), vpc)
    return owner, np.tile(np.arange(vpc), m), ids, np.sort(ids, axis=1)


def _outward(points, cells, owner, f, ids):
    """Face vertex order with the normal (3D) / right-hand side (2D) pointing away from vertex f."""
    ids = ids.copy()
    opposite = points[cells[owner, f]]
    a, b = points[ids[:, 0]], points[ids[:, 1]]
    if ids.shape[1] == 3:
        n = np.cross(b - a, points[ids[:, 2]] - a)
        flip = (n * (opposite - a)).sum(1) > 0
        ids[flip, 1], ids[flip, 2] = ids[flip, 2].copy(), ids[flip, 1].copy()
    else:
        # Edge a -> b with the cell on its left: outward normal (dy, -dx).
        d = b - a
        flip = (d[:, 1] * (opposite - a)[:, 0] - d[:, 0] * (opposite - a)[:, 1]) > 0
        ids[flip] = ids[flip][:, ::-1]
    return ids


def label_names(grid, labels):
    """{label: name} for the labels present: the grid's LabelNames field data where it names them,
    else REGION_NAMES, else label_L."""
    given = grid.GetFieldData().GetAbstractArray(contract.LabelNames) if grid.GetFieldData() else None
    binary = labels.max(initial=0) <= 1
    names = {}
    for L in (int(x) for x in np.unique(labels)):
        name = (given.GetComponentName(L) or "") if given is not None and L < given.GetNumberOfComponents() else ""
        names[L] = name or (REGION_NAMES[L] if binary or L == 0 else "label_%d" % L)
    return names


def pair_tag(a, b):
    """The boundary tag of the interface between labels a and b (several object labels)."""
    a, b = min(a, b), max(a, b)
    return PAIR_TAG0 + 256 * a + b


def boundary_faces(points, cells, labels, tolerance=1e-9):
    """Tagged boundary faces: (faces (k, vpc - 1), tags (k,)). Interface faces (two cells of different
    labels) point out of the higher label, tagged INTERFACE_TAG with labels 0 and 1 only, else by their
    pair (pair_tag); box faces (one cell) out of the box, tagged by side."""
    owner, f, ids, key = _faces(cells)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.ravel()
    hull = counts[inverse] == 1
    # Interface: of each shared face's two instances keep the one from the higher-labelled cell.
    order = np.lexsort((-labels[owner], inverse))
    first = np.ones(len(order), bool)
    first[1:] = inverse[order][1:] != inverse[order][:-1]
    pair_label = np.full(len(counts), -1)
    np.maximum.at(pair_label, inverse, labels[owner])
    low = np.full(len(counts), 1 << 30)
    np.minimum.at(low, inverse, labels[owner])
    interface = np.zeros(len(owner), bool)
    keep = order[first]
    interface[keep] = (counts[inverse[keep]] == 2) & (low[inverse[keep]] != pair_label[inverse[keep]])
    dim = cells.shape[1] - 1
    lo, hi = points[:, :dim].min(0), points[:, :dim].max(0)
    tags = np.full(len(owner), -1)
    if labels.max(initial=0) <= 1:
        tags[interface] = INTERFACE_TAG
    else:
        tags[interface] = PAIR_TAG0 + 256 * low[inverse[interface]] + pair_label[inverse[interface]]
    P = points[ids[hull]]
    hull_tags = np.full(hull.sum(), -1)
    for axis in range(dim):
        for s, bound in enumerate((lo[axis], hi[axis])):
            on = (np.abs(P[:, :, axis] - bound) <= tolerance * max(1.0, abs(bound))).all(axis=1)
            hull_tags[on & (hull_tags < 0)] = BOX_TAG0 + 2 * axis + s
    tags[hull] = hull_tags
    chosen = tags >= 0
    return _outward(points, cells, owner[chosen], f[chosen], ids[chosen]), tags[chosen]


def components_per_label(cells, labels):
    """{label: number of face-connected components of its cells}."""
    owner, _, _, key = _faces(cells)
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    same = inverse[order][1:] == inverse[order][:-1]
    a, b = owner[order][:-1][same], owner[order][1:][same]
    keep = labels[a] == labels[b]
    m = len(cells)
    graph = coo_matrix((np.ones(keep.sum()), (a[keep], b[keep])), shape=(m, m))
    _, component = connected_components(graph, directed=False)
    return {int(L): int(len(np.unique(component[labels == L]))) for L in np.unique(labels)}


def element_measures(points, cells):
    """Signed area (triangles, xy) or volume (tetrahedra) of every cell."""
    P = points[cells]
    if cells.shape[1] == 3:
        return 0.5 * np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])[:, 2]
    return np.einsum("ij,ij->i", P[:, 1] - P[:, 0], np.cross(P[:, 2] - P[:, 0], P[:, 3] - P[:, 0])) / 6.0


def tag_names(dim, regions=None):
    """{tag: name} of the boundary tags; `regions` ({label: name}) names the pair tags."""
    names = {INTERFACE_TAG: INTERFACE_NAME}
    names.update({BOX_TAG0 + s: BOX_SIDES[s] for s in range(2 * dim)})
    for a in regions or {}:
        for b in regions or {}:
            if a < b:
                names[pair_tag(a, b)] = "%s|%s" % (regions[a], regions[b])
    return names


def write(grid, base, unit="mm", formats=tuple(FORMATS)):
    """Writes base + suffix for each format; returns {format: path}."""
    import meshio
    points, cells, labels = grid_arrays(grid)
    vpc = cells.shape[1]
    dim = vpc - 1
    volume_type, face_type = ("tetra", "triangle") if vpc == 4 else ("triangle", "line")
    faces, tags = boundary_faces(points, cells, labels)
    region = label_names(grid, labels)
    present = sorted(region)
    blocks = [(volume_type, cells[labels == L]) for L in present]
    face_tags = sorted(set(tags.tolist()))
    face_blocks = [(face_type, faces[tags == t]) for t in face_tags]
    names = tag_names(dim, region)
    nodes = {names[t]: np.unique(faces[tags == t]) for t in face_tags}
    written = {}
    for fmt in formats:
        path = base + FORMATS[fmt]
        if fmt == "gmsh":
            field = {region[L]: np.array([L + 1, dim]) for L in present}
            field.update({names[t]: np.array([t, dim - 1]) for t in face_tags})
            physical = [np.full(len(c), L + 1) for L, (_, c) in zip(present, blocks)] + \
                       [np.full(len(c), t) for t, (_, c) in zip(face_tags, face_blocks)]
            mesh = meshio.Mesh(points, blocks + face_blocks, field_data=field,
                               cell_data={"gmsh:physical": physical, "gmsh:geometrical": physical})
            # Gmsh 2.2 (ASCII): meshio writes 4.1 only with per-node entity tags; 2.2 carries the same groups.
            meshio.write(path, mesh, file_format="gmsh22", binary=False)
        elif fmt == "medit":
            refs = [np.full(len(c), L) for L, (_, c) in zip(present, blocks)] + \
                   [np.full(len(c), t) for t, (_, c) in zip(face_tags, face_blocks)]
            meshio.write(path, meshio.Mesh(points, blocks + face_blocks, cell_data={"medit:ref": refs}), file_format="medit")
        elif fmt == "abaqus":
            sets = {region[L]: [np.arange(len(c)) if k == i else np.array([], int) for k in range(len(blocks))]
                    for i, (L, (_, c)) in enumerate(zip(present, blocks))}
            abaqus_nodes = {name.replace("|", "__"): ids for name, ids in nodes.items()}
            meshio.write(path, meshio.Mesh(points, blocks, cell_sets=sets, point_sets=abaqus_nodes), file_format="abaqus")
            _abaqus_node_fields(path)
        elif fmt == "exodus":
            meshio.write(path, meshio.Mesh(points, blocks, point_sets=nodes), file_format="exodus")
            _exodus_info(path, ["FeatureMesh labelled mesh", "length unit: %s" % unit] +
                         ["element block %d: %s" % (i + 1, region[L]) for i, L in enumerate(present)])
        written[fmt] = path
    return written


def _abaqus_node_fields(path, digits=9):
    """Rewrites the *NODE lines of an Abaqus deck with `digits` significant digits: meshio writes
    22-character coordinates, and CalculiX reads fields of at most 20 characters ("*ERROR reading
    *NODE"). Nine digits keep a millimetre mesh of a metre-sized box to a nanometre."""
    with open(path) as f:
        lines = f.read().split("\n")
    in_nodes = False
    for i, line in enumerate(lines):
        if line.startswith("*"):
            in_nodes = line.strip().upper().startswith("*NODE") and not line.strip().upper().startswith("*NODE ")
            continue
        if in_nodes and line.strip():
            fields = line.split(",")
            lines[i] = ", ".join([fields[0].strip()] + ["%.*g" % (digits, float(x)) for x in fields[1:]])
    with open(path, "w") as f:
        f.write("\n".join(lines))


def _exodus_info(path, lines):
    """Exodus II's info records (the format's place for free text such as the length unit)."""
    import netCDF4
    with netCDF4.Dataset(path, "a") as root:
        if "num_info" not in root.dimensions:
            root.createDimension("num_info", len(lines))
        if "len_line" not in root.dimensions:
            root.createDimension("len_line", 81)
        info = root.createVariable("info_records", "S1", ("num_info", "len_line"))
        info.set_auto_mask(False)
        data = np.zeros((len(lines), 81), dtype="S1")
        for i, line in enumerate(lines):
            encoded = line.encode()[:80]
            data[i, :len(encoded)] = np.frombuffer(encoded, dtype="S1")
        info[:] = data


def report(grid, bins=np.arange(0, 181, 5)):
    """Per label: element count, measure (world units), face-connected components; quality histogram
    (smallest angle in 2D, smallest dihedral angle in 3D, degrees) of each label's elements."""
    from . import metrics
    points, cells, labels = grid_arrays(grid)
    region = label_names(grid, labels)
    measures = np.abs(element_measures(points, cells))
    components = components_per_label(cells, labels)
    quality = metrics.element_angles(points, cells).min(axis=1)
    out = {}
    for L in np.unique(labels):
        sel = labels == L
        hist, _ = np.histogram(quality[sel], bins)
        out[region[int(L)]] = {
            "elements": int(sel.sum()), "measure": float(measures[sel].sum()), "components": components[int(L)],
            "min_quality_degrees": float(quality[sel].min()), "quality_histogram": hist.tolist()}
    return {"labels": out, "histogram_bins_degrees": bins.tolist()}
