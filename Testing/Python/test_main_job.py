"""The main job's script on the bundled nuclei case with cut options: it writes every file, and its
report gives the options used, Dice, object components whose areas sum to the label image's, and the
mesh quality before and after smoothing (stage 3 runs by default)."""
import json
import os
import shutil
import subprocess
import tempfile

import fmtest as ft

d = ft.case_dir("nuclei-dsb2018")
out = tempfile.mkdtemp()
script = os.path.join(ft.fm.ROOT, "scripts", "featuremesh_segment.py")
run = subprocess.run([shutil.which("pvpython"), script, os.path.join(d, "image.mha"),
                      "--object-seeds", os.path.join(d, "seeds_object.csv"),
                      "--background-seeds", os.path.join(d, "seeds_background.csv"),
                      "--truth", os.path.join(d, "truth.mha"), "--out", out,
                      "--lambda", "0.5", "--connectivity", "seeded"], capture_output=True, text=True)
ft.check(run.returncode == 0, "the script exits 0 (stderr: %s)" % run.stderr[-800:])
base = os.path.join(out, "nuclei-dsb2018")
for suffix in ("_mesh.vtu", "_boundary.vtp", "_labels.vti", "_report.json", "_view.png"):
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
print("all main-job checks passed")
