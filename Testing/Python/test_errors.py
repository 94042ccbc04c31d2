"""Errors as a ParaView user meets them: a failing filter reports its error once (ParaView updates
every output port, and a failed run once repeated itself per port), fixing the input re-runs it,
and the failure does not cascade into a misleading error downstream."""
import shutil
import subprocess
import sys

import fmtest as ft

if len(sys.argv) > 1:  # child: a failing Feature Nodes and a failing Super-Voxel Cut, then fixes
    c = ft.fm.Case(ft.case_dir("nuclei-dsb2018"))
    nodes = c.feature_nodes(GaussianSigma=-1)
    mesh = c.mesh(nodes)
    mesh.UpdatePipeline()
    nodes.GaussianSigma = 0.7
    mesh.UpdatePipeline()
    print("MESH CELLS", ft.fetch(mesh).GetNumberOfCells(), flush=True)
    cut = ft.SuperVoxelCut(Mesh=mesh, ObjectSeeds=ft.PolyPointSource(Points=[9999, 0, 0]), BackgroundSeeds=c.background_seeds,
                           Image=c.image)
    cut.UpdatePipeline()
    cut.ObjectSeeds = c.object_seeds
    cut.UpdatePipeline()
    print("CUT CELLS", ft.fetch(cut).GetNumberOfCells(), flush=True)
    fresh = c.mesh(c.feature_nodes())
    fresh.UpdatePipeline()
    print("FRESH CELLS", ft.fetch(fresh).GetNumberOfCells(), flush=True)
    sys.exit(0)

run = subprocess.run([shutil.which("pvpython"), __file__, "child"], capture_output=True, text=True, timeout=300)
log = run.stdout + run.stderr
ft.check(log.count("Feature Nodes: the Gaussian and Hessian sigmas") == 1, "Feature Nodes reports its error once (%d)" % log.count("Feature Nodes: the Gaussian"))
ft.check("Delaunay Image Mesh:" not in log, "the failure does not cascade into a Delaunay Image Mesh error")
ft.check(log.count("Super-Voxel Cut: 1 of 1 object seeds fall outside") == 1, "Super-Voxel Cut reports its error once")
fresh = [line.split()[-1] for line in log.splitlines() if line.startswith("FRESH CELLS")]
ft.check(len(fresh) == 1 and int(fresh[0]) > 1000, "a fresh pipeline meshes the image (%s cells)" % fresh)
ft.check(fresh and "MESH CELLS %s" % fresh[0] in log, "fixing the property re-runs the pipeline: the fresh pipeline's mesh")
ft.check(fresh and "CUT CELLS %s" % fresh[0] in log, "fixing the seeds re-runs the cut on it")
