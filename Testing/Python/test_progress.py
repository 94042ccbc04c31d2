"""Progress and abort on the largest case (BraTS, 240x240x155): every filter reports progress at
least every 0.5 s; an abort during the max-flow (or the smoothing's TetGen refinement, RSP's paths, or the
volume mesh following the smoothed boundary) returns within
a second with an empty output; the aborted filter runs again on the next update and gives its full
result."""
import time

import fmtest as ft

case = ft.fm.Case(ft.case_dir("brain-tumour-brats-0005"))
MAX_GAP = 0.5


def watch(proxy):
    """Updates the proxy, recording when its VTK object reports progress; returns (gaps, events)."""
    algorithm = proxy.GetClientSideObject()
    stamps = []
    tag = algorithm.AddObserver("ProgressEvent", lambda o, e: stamps.append((time.perf_counter(), o.GetProgress())))
    start = time.perf_counter()
    proxy.UpdatePipeline()
    end = time.perf_counter()
    algorithm.RemoveObserver(tag)
    times = [start] + [t for t, _ in stamps] + [end]
    return max(b - a for a, b in zip(times, times[1:])), len(stamps), end - start


nodes = case.feature_nodes()
mesh = case.mesh(nodes)
smoothed = case.smoothing(mesh)
cut = case.super_voxel_cut(mesh)
for name, proxy in (("Feature Nodes", nodes), ("Delaunay Image Mesh", mesh), ("Image Mesh Smoothing", smoothed),
                    ("Super-Voxel Cut", cut), ("Voxel Cut", case.voxel_cut()), ("RSP Edge Enhancement", case.rsp()),
                    ("RSP Edge Enhancement at full resolution", case.rsp(MaximumPathVoxels=0)),
                    ("Segmentation Surface Smoothing", case.surface_smoothing(cut))):
    gap, events, seconds = watch(proxy)
    ft.check(gap <= MAX_GAP, "%s on BraTS: %d progress events over %.2f s, longest gap %.3f s (<= %.1f s)" % (name, events, seconds, gap, MAX_GAP))

def abort_after(proxy, fraction):
    """Updates the proxy, asking it to abort once its progress passes `fraction`; returns the
    seconds from the request to the return (None when it was never asked) and whether the output
    was then empty. The abort flag is cleared afterwards, so the next update runs again."""
    algorithm = proxy.GetClientSideObject()
    asked = []

    def abort(o, e):
        if o.GetProgress() > fraction and not asked:
            asked.append(time.perf_counter())
            o.SetAbortExecute(1)

    tag = algorithm.AddObserver("ProgressEvent", abort)
    proxy.UpdatePipeline()
    returned = time.perf_counter()
    algorithm.RemoveObserver(tag)
    empty = ft.fetch(proxy).GetNumberOfPoints() == 0
    algorithm.SetAbortExecute(0)
    return (returned - asked[0] if asked else None), empty


# Abort in the middle of the voxel cut's max-flow (its longest step), from a progress observer.
vc = case.voxel_cut()
after, empty = abort_after(vc, 0.7)
ft.check(after is not None and after < 1.0, "Voxel Cut returns %.2f s after an abort during the flow (< 1 s)" % (after or -1))
ft.check(empty, "the aborted output is empty")
vc.UpdatePipeline()
labels = ft.fm.labels(vc, 0)
ft.check(labels.size == 240 * 240 * 155 and 0 < labels.sum() < labels.size, "the next update runs the cut again (%d object voxels)" % labels.sum())

# The same for the super-voxel cut, aborted in its setup.
sv = case.super_voxel_cut(mesh)
algorithm = sv.GetClientSideObject()
tag = algorithm.AddObserver("ProgressEvent", lambda o, e: o.SetAbortExecute(1) if o.GetProgress() > 0.3 else None)
sv.UpdatePipeline()
algorithm.RemoveObserver(tag)
ft.check(ft.fetch(sv).GetNumberOfCells() == 0, "an aborted Super-Voxel Cut has an empty output")
algorithm.SetAbortExecute(0)
sv.UpdatePipeline()
ft.check(ft.fetch(sv).GetNumberOfCells() > 0, "and runs again on the next update")

# Image Mesh Smoothing, aborted during its refinement (TetGen runs beside a heartbeat).
sm = case.smoothing(mesh)
after, empty = abort_after(sm, 0.45)
ft.check(after is not None and after < 1.0, "Image Mesh Smoothing returns %.2f s after an abort during refinement (< 1 s)" % (after or -1))
ft.check(empty, "an aborted Image Mesh Smoothing has an empty output")
sm.UpdatePipeline()
ft.check(ft.fetch(sm).GetNumberOfCells() > ft.fetch(mesh).GetNumberOfCells(), "and runs again on the next update")

# RSP Edge Enhancement at full resolution, aborted during its shortest paths.
rsp = case.rsp(MaximumPathVoxels=0)
after, empty = abort_after(rsp, 0.5)
ft.check(after is not None and after < 1.0, "RSP Edge Enhancement returns %.2f s after an abort during the paths (< 1 s)" % (after or -1))
ft.check(empty, "an aborted RSP Edge Enhancement has an empty output")
rsp.UpdatePipeline()
ft.check(ft.array(ft.fetch(rsp), ft.names.EdgeConfidence).max() > 0, "and runs again on the next update")

# Segmentation Surface Smoothing, aborted while the labelled mesh follows the boundary.
ss = case.surface_smoothing(cut)
after, empty = abort_after(ss, 0.3)
ft.check(after is not None and after < 1.0, "Segmentation Surface Smoothing returns %.2f s after an abort (< 1 s)" % (after or -1))
ft.check(empty, "an aborted Segmentation Surface Smoothing has an empty output")
ss.UpdatePipeline()
ft.check(ft.fetch(ss).GetNumberOfCells() > 0 and ft.fetch(ss, 1).GetNumberOfCells() > 0, "and runs again on the next update")
