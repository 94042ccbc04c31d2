"""The README's pvpython snippet, as written (FM pointed at this clone), runs from another directory
and writes the labelled mesh and the picture it promises."""
import os
import re
import shutil
import subprocess

from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

import fmtest as ft

readme = open(os.path.join(ft.fm.ROOT, "README.md")).read()
blocks = re.findall(r"```python\n(.*?)```", readme, re.S)
ft.check(len(blocks) == 1, "the README has one pvpython snippet")
code = blocks[0]
ft.check('FM = "/path/to/FeatureMesh"' in code, "the snippet says where to point FM")
code = code.replace('FM = "/path/to/FeatureMesh"', "FM = %r" % ft.fm.ROOT)
work = ft.scratch("featuremesh-readme-")
with open(os.path.join(work, "snippet.py"), "w") as f:
    f.write(code)
# The snippet's plugin path is the build tree's; point it at this build's plugin when that differs.
env = dict(os.environ)
run = subprocess.run([shutil.which("pvpython"), "snippet.py"], cwd=work, capture_output=True, text=True, env=env, timeout=600)
ft.check(run.returncode == 0, "the snippet runs from %s (exit %d)%s" % (work, run.returncode, "" if run.returncode == 0 else ": " + run.stderr[-800:]))
vtu, png = os.path.join(work, "nuclei_labelled.vtu"), os.path.join(work, "nuclei_cut.png")
ft.check(os.path.isfile(png) and os.path.getsize(png) > 10000, "it writes nuclei_cut.png")
ft.check(os.path.isfile(vtu), "it writes nuclei_labelled.vtu")
if os.path.isfile(vtu):
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(vtu)
    r.Update()
    label = r.GetOutput().GetCellData().GetArray(ft.names.Label)
    ft.check(label is not None and 0 < ft.v2n(label).sum() < label.GetNumberOfTuples(), "the written mesh holds object and background elements")
