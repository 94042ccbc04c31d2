"""Measures for the benchmark: the mesh as a super-pixel partition, SLIC at the same count, and the
seeded peers (random walker, watershed). numpy / scipy / scikit-image only, no ParaView.

Every array is a volume in (z, y, x) order (2D images have z = 1); `truth` is boolean.
"""
import time

import numpy as np
from scipy import ndimage as ndi
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n
from vtkmodules.vtkCommonCore import vtkDoubleArray

__all__ = ["oracle_from_fractions", "partition_scores", "boundary_recall", "unit_range", "slic_at_count",
           "seed_markers", "random_walker_peer", "watershed_peer", "RANDOM_WALKER_BETA"]

# On the unit_range image scikit-image's weights are exp(-beta dI^2 / (10 std I)), the same for every
# image. Its default 130 left the walk close to pure diffusion here (Dice 0.01-0.20 on nuclei, liver,
# EM-00, BraTS-0006); of 130 / 1e3 / 5e3 / 2e4 / 5e4 / 2e5 on those and retina-21, 2e5 has the best
# mean (0.63), so the peer gets it on every case.
RANDOM_WALKER_BETA = 2e5


def oracle_from_fractions(fraction, count, truth_voxels, total_voxels):
    """Oracle Dice and ASA of a partition from each segment's object fraction and voxel count.

    Oracle Dice: every segment takes its majority reference label. ASA (achievable segmentation
    accuracy): the fraction of voxels that agree with their segment's majority label.
    """
    fraction, count = np.asarray(fraction, float), np.asarray(count, float)
    chosen = fraction > 0.5
    hit = (fraction * count)[chosen].sum()
    dice = 2.0 * hit / max(1.0, count[chosen].sum() + truth_voxels)
    asa = (np.maximum(fraction, 1.0 - fraction) * count).sum() / max(1.0, total_voxels)
    return float(dice), float(asa)


def _edges(labels):
    """Voxels with a face neighbour of another label (both sides of each boundary)."""
    b = np.zeros(labels.shape, bool)
    for axis in range(labels.ndim):
        if labels.shape[axis] < 2:
            continue
        lo = [slice(None)] * labels.ndim
        hi = [slice(None)] * labels.ndim
        lo[axis], hi[axis] = slice(0, -1), slice(1, None)
        diff = labels[tuple(lo)] != labels[tuple(hi)]
        b[tuple(lo)] |= diff
        b[tuple(hi)] |= diff
    return b


def boundary_recall(segments, truth, tolerance=1):
    """Fraction of the reference's boundary voxels within `tolerance` voxels (chessboard) of a
    segment boundary voxel."""
    ref = _edges(truth.astype(np.uint8))
    near = _edges(segments)
    if tolerance > 0:
        structure = np.ones((3,) * segments.ndim, bool)
        if segments.shape[0] == 1:  # 2D: no neighbours across z
            structure[0] = structure[2] = False
        near = ndi.binary_dilation(near, structure, iterations=tolerance)
    return float((ref & near).sum() / max(1, ref.sum()))


def partition_scores(segments, truth):
    """K, oracle Dice, ASA and boundary recall of a label image of segments (ids 0..K-1; -1, a voxel
    no element owns, counts as one segment more)."""
    segments = np.asarray(segments)
    if segments.min() < 0:
        segments = np.where(segments < 0, segments.max() + 1, segments)
    flat = segments.ravel()
    k = int(flat.max()) + 1
    count = np.bincount(flat, minlength=k)
    obj = np.bincount(flat, weights=truth.ravel().astype(float), minlength=k)
    used = count > 0
    fraction = np.where(used, obj / np.maximum(count, 1), 0.0)
    dice, asa = oracle_from_fractions(fraction[used], count[used], truth.sum(), truth.size)
    return {"K": int(used.sum()), "oracle_dice": dice, "asa": asa, "boundary_recall": boundary_recall(segments, truth)}


def unit_range(image):
    """The image mapped to [0, 1] by its 0.5 and 99.5 percentiles (clipped), as float32."""
    lo, hi = np.percentile(image, [0.5, 99.5])
    if not hi > lo:
        hi = lo + 1.0
    return np.clip((image.astype(np.float32) - lo) / (hi - lo), 0.0, 1.0)


def _skimage_spacing(volume, spacing):
    """Spacing (x, y, z) in the axis order of _squeeze(volume): (y, x) or (z, y, x)."""
    sp = np.asarray(spacing, float)
    return sp[:2][::-1] if volume.shape[0] == 1 else sp[::-1]


def _slic(unit, n, compactness, spacing):
    from skimage.segmentation import slic
    s = slic(_squeeze(unit), n_segments=int(n), compactness=compactness, channel_axis=None, start_label=0,
             spacing=_skimage_spacing(unit, spacing), enforce_connectivity=True)
    return s.reshape(unit.shape)


def slic_at_count(unit, truth, k, spacing, compactness=(0.01, 0.03, 0.1, 0.3)):
    """SLIC (scikit-image) scores interpolated to K segments, with its best compactness.

    Each compactness runs once near K; the best by oracle Dice then runs again on the other side of
    K, and the two runs' scores are interpolated linearly in the segment count. Returns the scores,
    the compactness and the seconds of one SLIC run near K.
    """
    runs = {}
    for c in compactness:
        t = time.perf_counter()
        s = _slic(unit, k, c, spacing)
        seconds = time.perf_counter() - t
        runs[c] = (partition_scores(s, truth), seconds)
    best = max(compactness, key=lambda c: runs[c][0]["oracle_dice"])
    first, seconds = runs[best]
    # SLIC returns about as many segments as asked, never exactly (its seeds lie on a grid whose
    # step is an integer, so counts jump): ask again, scaled by how far the last run landed, until
    # runs lie on both sides of K (at most four more runs).
    below = above = None

    def side(n, r):
        nonlocal below, above
        if r["K"] <= k and (below is None or r["K"] > below[1]["K"]):
            below = (n, r)
        if r["K"] > k and (above is None or r["K"] < above[1]["K"]):
            above = (n, r)

    side(float(k), first)
    for _ in range(4):
        if below and above:
            break
        n, r = below or above
        n = n * k / max(1, r["K"]) * (1.15 if above is None else 0.85)
        side(n, partition_scores(_slic(unit, n, best, spacing), truth))
    below = below[1] if below else None
    above = above[1] if above else None
    if below is None or above is None:
        out = dict(below or above)
    else:
        w = (k - below["K"]) / max(1, above["K"] - below["K"])
        out = {key: below[key] + w * (above[key] - below[key]) for key in ("oracle_dice", "asa", "boundary_recall")}
        out["K"] = k
    out["bracket"] = (below["K"] if below else None, above["K"] if above else None)
    out["compactness"] = best
    out["seconds"] = seconds
    return out


def seed_markers(shape, object_index, background_index):
    """A marker volume: 1 at the object seed voxels, 2 at the background ones, 0 elsewhere.
    Seeds are (i, j, k) voxel indices."""
    m = np.zeros(shape, np.int32)
    for value, seeds in ((1, object_index), (2, background_index)):
        for i, j, k in seeds:
            m[k, j, i] = value
    return m


def _squeeze(a):
    return a[0] if a.shape[0] == 1 else a


# The random walker's conjugate-gradient solve is the slow part: over this many voxels it runs on
# the image averaged over 2 x 2 x 2 blocks (a BraTS volume at full size ran > 11 min unfinished).
RANDOM_WALKER_FULL_SIZE = 2000000


def _block_mean(a, f):
    pad = [(0, (-s) % f) if s > 1 else (0, 0) for s in a.shape]
    a = np.pad(a, pad, mode="edge")
    shape = []
    for s in a.shape:
        shape += [s // f, f] if s > 1 else [1, 1]
    return a.reshape(shape).mean(axis=tuple(range(1, 2 * a.ndim, 2)))


def random_walker_peer(unit, markers, spacing):
    """scikit-image's random walker on the unit-range image; returns (object mask, seconds, scale).
    Over RANDOM_WALKER_FULL_SIZE voxels it runs on 2 x 2 x 2 block means (each seed marks its block)
    and the labels return to full size by nearest neighbour: scale 2."""
    from skimage.segmentation import random_walker
    t = time.perf_counter()
    scale = 2 if unit.size > RANDOM_WALKER_FULL_SIZE else 1
    image, seeds, sp = unit, markers, np.asarray(spacing, float)
    if scale > 1:
        image = _block_mean(unit, scale)
        seeds = np.zeros(image.shape, np.int32)
        z, y, x = np.nonzero(markers)
        seeds[z // (scale if unit.shape[0] > 1 else 1), y // scale, x // scale] = markers[z, y, x]
        sp = sp * scale
    r = random_walker(_squeeze(image), _squeeze(seeds), beta=RANDOM_WALKER_BETA, mode="cg_j", tol=1e-3,
                      spacing=_skimage_spacing(image, sp))
    r = r.reshape(image.shape) == 1
    if scale > 1:
        r = r.repeat(scale, 0).repeat(scale, 1).repeat(scale, 2)[: unit.shape[0], : unit.shape[1], : unit.shape[2]]
    return r, time.perf_counter() - t, scale


def watershed_peer(unit, markers, spacing):
    """A seeded watershed (scikit-image) on the gradient magnitude of the unit-range image smoothed
    with a one-voxel Gaussian; returns (object mask, seconds)."""
    from skimage.segmentation import watershed
    t = time.perf_counter()
    image = _squeeze(unit)
    gradient = ndi.gaussian_gradient_magnitude(image, 1.0)
    r = watershed(gradient, _squeeze(markers))
    return (r.reshape(unit.shape) == 1), time.perf_counter() - t, 1


def element_angles(points, cells):
    """Angles of every element in degrees: triangles (n, 3) -> their three angles, tetrahedra
    (n, 4) -> their six dihedral angles; points (m, 3) in world (or frame) coordinates."""
    P = np.asarray(points, float)[np.asarray(cells)]
    if P.shape[1] == 3:
        out = []
        for k in range(3):
            u, w = P[:, (k + 1) % 3] - P[:, k], P[:, (k + 2) % 3] - P[:, k]
            out.append(np.degrees(np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), (u * w).sum(1))))
        return np.stack(out, axis=1)
    # Face f is opposite vertex f; outward normals; dihedral at the edge of faces k, l = pi - angle(n_k, n_l).
    n = []
    for f in range(4):
        a, b, c = P[:, (f + 1) % 4], P[:, (f + 2) % 4], P[:, (f + 3) % 4]
        nf = np.cross(b - a, c - a)
        nf *= -np.sign((nf * (P[:, f] - a)).sum(1))[:, None]
        n.append(nf / np.linalg.norm(nf, axis=1)[:, None])
    out = [np.degrees(np.arccos(np.clip(-(n[k] * n[l]).sum(1), -1, 1))) for k in range(4) for l in range(k + 1, 4)]
    return np.stack(out, axis=1)


def mesh_quality(points, cells):
    """min, 1st percentile of the per-element minimum, and max angle (dihedral for tetrahedra)."""
    a = element_angles(points, cells)
    lo = a.min(axis=1)
    return {"min": float(lo.min()), "p1": float(np.percentile(lo, 1)), "max": float(a.max())}


def triangle_samples(surface, levels=2):
    """Area-weighted samples of a triangle surface (vtkPolyData): the centroids of the 4**levels
    equal sub-triangles of each triangle, and their areas (works on non-manifold surfaces too)."""
    P = v2n(surface.GetPoints().GetData()).astype(float)
    F = v2n(surface.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    a, b, c = P[F[:, 0]], P[F[:, 1]], P[F[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    n = 2 ** levels
    # Barycentric (u, v) of the sub-triangles' centroids: n*n upward ones and n*(n-1)/2 ... downward.
    uv = [((i + 1 / 3) / n, (j + 1 / 3) / n) for i in range(n) for j in range(n - i)]
    uv += [((i + 2 / 3) / n, (j + 2 / 3) / n) for i in range(n - 1) for j in range(n - 1 - i)]
    samples = [a + u * (b - a) + v * (c - a) for u, v in uv]
    return np.concatenate(samples), np.tile(area / (n * n), len(uv))


def _distances_to(points, surface):
    """Unsigned distance of each point to the triangles of `surface` (exact point-triangle distance)."""
    from vtkmodules.vtkFiltersCore import vtkImplicitPolyDataDistance
    from vtkmodules.util.numpy_support import numpy_to_vtk
    implicit = vtkImplicitPolyDataDistance()
    implicit.SetInput(surface)
    out = vtkDoubleArray()
    implicit.FunctionValue(numpy_to_vtk(np.ascontiguousarray(points, dtype=float), deep=1), out)
    return np.abs(v2n(out))


def _weighted_percentile(values, weights, q):
    order = np.argsort(values)
    cumulative = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cumulative, q / 100.0 * cumulative[-1])])


def surface_distances(surface, reference, levels=2):
    """Symmetric surface distance between two triangle surfaces (world units), area-weighted both ways:
    {"mean": mean symmetric distance (the two directed means averaged), "hd95": the larger of the
    two directed 95th percentiles, "mean_to_reference", "mean_from_reference"}."""
    a, wa = triangle_samples(surface, levels)
    b, wb = triangle_samples(reference, 0)
    dab, dba = _distances_to(a, reference), _distances_to(b, surface)
    mab, mba = float((dab * wa).sum() / wa.sum()), float((dba * wb).sum() / wb.sum())
    return {"mean": 0.5 * (mab + mba), "hd95": max(_weighted_percentile(dab, wa, 95), _weighted_percentile(dba, wb, 95)),
            "mean_to_reference": mab, "mean_from_reference": mba}


def mask_surface(image, scalars):
    """The 0.5 iso-surface (flying edges) of a 0/1 mask given as a vtkImageData frame and its flat array."""
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkFiltersCore import vtkFlyingEdges3D
    from vtkmodules.util.numpy_support import numpy_to_vtk
    mask = vtkImageData()
    mask.CopyStructure(image)
    array = numpy_to_vtk(np.ascontiguousarray(scalars, dtype=np.float32), deep=1)
    array.SetName("mask")
    mask.GetPointData().SetScalars(array)
    fe = vtkFlyingEdges3D()
    fe.SetInputData(mask)
    fe.SetValue(0, 0.5)
    fe.ComputeNormalsOff()
    fe.Update()
    return fe.GetOutput()


def without_box_faces(surface, bounds, tolerance=1e-6):
    """The triangles of `surface` that do not lie in a plane of the box `bounds` (xmin, xmax, ymin, ...):
    the object's interface without its caps on the image box (where the reference's iso-surface is open)."""
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.util.numpy_support import numpy_to_vtkIdTypeArray
    P = v2n(surface.GetPoints().GetData()).astype(float)
    F = v2n(surface.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    on_box = np.zeros(len(F), bool)
    for axis in range(3):
        for bound in bounds[2 * axis: 2 * axis + 2]:
            on_box |= (np.abs(P[F, axis] - bound) <= tolerance * max(1.0, abs(bound))).all(axis=1)
    kept = F[~on_box]
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 3 * len(kept) + 1, 3, dtype=np.int64), deep=1),
                  numpy_to_vtkIdTypeArray(kept.ravel().astype(np.int64), deep=1))
    out = vtkPolyData()
    out.SetPoints(surface.GetPoints())
    out.SetPolys(cells)
    return out


def bending(surface):
    """Mean angle (degrees) between the normals of two triangles of `surface` sharing an edge, over
    the edges in exactly two triangles: 0 for a plane, large for a staircase of element faces."""
    P = v2n(surface.GetPoints().GetData()).astype(float)
    F = v2n(surface.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    n = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    edges = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    face = np.tile(np.arange(len(F)), 3)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    edges, face = edges[order], face[order]
    same = (edges[1:] == edges[:-1]).all(axis=1)
    # Edges in exactly two faces: equal to the next, and neither to the one before nor after the pair.
    before = np.r_[False, same[:-1]]
    after = np.r_[same[1:], False]
    pair = same & ~before & ~after
    a, b = face[:-1][pair], face[1:][pair]
    cosines = np.clip(np.einsum("ij,ij->i", n[a], n[b]), -1.0, 1.0)
    return float(np.degrees(np.arccos(cosines)).mean()) if len(a) else float("nan")


def draw_labelled_seeds(labels, counts, rng, erosion=2.0, band=(3.0, 15.0)):
    """New seeds as the shared data's generator draws them (its README): `counts[l]` seeds of each
    label l > 0 at random from that label eroded by `erosion` voxels, `counts[0]` background seeds
    from the band `band` voxels around the union of the labels (Euclidean distances in voxels).
    `labels` is a label volume (0 background); returns {label: [(i, j, k), ...]}."""
    volume = labels.reshape(labels.shape if labels.ndim == 3 else (1,) + labels.shape)
    flat = _squeeze(volume)
    picks = {}
    for label in sorted(l for l in counts if l > 0) + [0] * (0 in counts):
        if label == 0:
            outside = ndi.distance_transform_edt(flat == 0)
            where = (outside >= band[0]) & (outside <= band[1])
        else:
            where = ndi.distance_transform_edt(flat == label) > erosion
        candidates = np.flatnonzero(where.reshape(volume.shape))
        if len(candidates) < counts[label]:
            raise ValueError("only %d candidate voxels for %d seeds of label %d" % (len(candidates), counts[label], label))
        chosen = np.sort(rng.choice(candidates, size=counts[label], replace=False))
        k, j, i = np.unravel_index(chosen, volume.shape)
        picks[label] = [(int(a), int(b), int(c)) for a, b, c in zip(i, j, k)]
    return picks


def draw_seeds(truth, n_object, n_background, rng, erosion=2.0, band=(3.0, 15.0)):
    """draw_labelled_seeds for one object (`truth` boolean): (object, background) lists of (i, j, k)."""
    picks = draw_labelled_seeds(np.asarray(truth).astype(np.uint8), {1: n_object, 0: n_background}, rng, erosion, band)
    return picks[1], picks[0]


def next_seed(result, truth, spacing):
    """(index (k, j, i), is_object) of the robot user's next seed (benchmark_clicks.py): the most interior
    voxel of the largest error region of `result` against `truth` (boolean arrays), or None when the
    result is right."""
    best = None
    for wrong, is_object in ((result & ~truth, False), (~result & truth, True)):
        labels, n = ndi.label(wrong)
        if n == 0:
            continue
        sizes = np.bincount(labels.ravel())[1:]
        k = int(np.argmax(sizes)) + 1
        if best is None or sizes[k - 1] > best[0]:
            best = (sizes[k - 1], labels == k, is_object)
    if best is None:
        return None
    region = best[1]
    # Distance to the region's border: the image's outside counts as border too.
    padded = np.pad(region, 1)
    distance = ndi.distance_transform_edt(padded, sampling=spacing[::-1])[1:-1, 1:-1, 1:-1]
    return np.unravel_index(int(np.argmax(distance)), region.shape), best[2]
