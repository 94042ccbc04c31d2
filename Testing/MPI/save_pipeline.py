"""Run under mpirun -np N pvbatch: the pipeline on the bundled cases, saved in parallel formats."""
import os
import sys

import featuremesh as fm

fm.load_plugin()
import paraview.simple as ps

out = sys.argv[1]
for name in ("nuclei-dsb2018", "liver-ct-totalseg"):
    c = fm.Case(fm.case_dir(name))
    nodes, mesh, cut = c.pipeline()
    cut.UpdatePipeline()
    ps.SaveData(os.path.join(out, name + "_labelled.pvtu"), proxy=ps.OutputPort(cut, 0))
    ps.SaveData(os.path.join(out, name + "_labels.pvti"), proxy=ps.OutputPort(cut, 2))
    ps.SaveData(os.path.join(out, name + "_fem.pvtu"), proxy=ps.OutputPort(c.surface_smoothing(cut), 1))
    ps.SaveData(os.path.join(out, name + "_voxelcut.pvti"), proxy=c.voxel_cut())
