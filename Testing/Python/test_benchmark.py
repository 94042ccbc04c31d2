"""The benchmark on the bundled cases (the shared data hidden): it prints the segmentation table with
the peer columns and the super-pixel table, and its figures are consistent: the mesh's oracle Dice
bounds every labelling of its elements, the super-voxel cut's elements included (its label image,
refined on the voxels along the cut, may pass it); scores lie in [0, 1]; the SLIC runs bracket K."""
import csv
import os
import re
import shutil
import subprocess

import fmtest as ft

out = os.path.join(ft.scratch(), "bench")
env = dict(os.environ, FEATUREMESH_SHARED_DATA=os.path.join(out, "absent"))
script = os.path.join(ft.fm.ROOT, "scripts", "benchmark.py")
run = subprocess.run([shutil.which("pvpython"), script, "--runs", "1", "--out", out], env=env, capture_output=True, text=True)
print(run.stdout[-3000:])
ft.check(run.returncode == 0, "benchmark.py exits 0 (stderr: %s)" % run.stderr[-500:])
ft.check("## Speed" in run.stdout and "## Mesh quality" in run.stdout and "## The mesh as super-pixels" in run.stdout and "dice_random_walker" in run.stdout and "dice_watershed" in run.stdout,
         "the printed tables hold the super-pixel table and the peer columns")
ft.check(re.search(r"fresh memory [0-9]+ ms per 100 MB \(default malloc\)", run.stdout) is not None,
         "the machine line gives the cost of fresh memory under the default malloc")
rows = list(csv.DictReader(open(out + ".csv"))) if os.path.isfile(out + ".csv") else []
ft.check(sorted(r["case"] for r in rows) == ["liver-ct-totalseg", "nuclei-dsb2018"], "both bundled cases in the CSV")
for r in rows:
    v = {k: float(x) for k, x in r.items() if k not in ("case", "slic_bracket") and x != ""}
    scores = [v[k] for k in v if k.startswith(("dice_", "oracle_", "asa_", "boundary_recall_"))]
    ft.check(all(0.0 <= s <= 1.0 for s in scores), "%s: every score in [0, 1]" % r["case"])
    ft.check(v["oracle_dice_mesh"] >= v["dice_elements"] - 1e-9,
             "%s: the mesh's oracle Dice %.3f bounds the super-voxel cut's elements' %.3f" % (r["case"], v["oracle_dice_mesh"], v["dice_elements"]))
    ft.check(v["dice_supervoxel"] >= v["dice_elements"] - 0.005,
             "%s: the refined label image %.3f is no worse than its elements' %.3f" % (r["case"], v["dice_supervoxel"], v["dice_elements"]))
    ft.check(v["K"] == v["elements_with_voxels"] <= v["elements"],
             "%s: K %d = the elements owning voxels (%d of %d)" % (r["case"], v["K"], v["elements_with_voxels"], v["elements"]))
    low, high = (int(x) if x != "None" else None for x in r["slic_bracket"].split("-"))
    ft.check(low is not None and high is not None and low <= v["K"] <= high,
             "%s: SLIC runs bracket K (%s)" % (r["case"], r["slic_bracket"]))
    ft.check(abs(v["speedup"] - v["voxel_cut_s"] / v["total_s"]) < 1e-6 * v["speedup"] and
             abs(v["total_s"] - sum(v[k] for k in ("nodes_s", "mesh_s", "smoothing_s", "cut_s"))) < 1e-9 and
             abs(v["recut_speedup"] - v["voxel_cut_s"] / v["recut_s"]) < 1e-6 * v["recut_speedup"],
             "%s: the speed table's total and ratios follow from its times" % r["case"])
    if r["case"] == "liver-ct-totalseg":
        ft.check(v.get("mesh3_s", 0) > 0 and abs(v["classic_s"] - v["voxel_cut_s"] - v["mesh3_s"]) < 1e-9,
                 "%s: the classic pipeline (voxel cut %.2f s + CGAL Mesh_3 %.2f s) is timed" % (r["case"], v["voxel_cut_s"], v.get("mesh3_s", 0)))
    ft.check(v["components"] >= 1, "%s: object components reported" % r["case"])
    ft.check(v["min_angle_smoothed"] > v["min_angle_delaunay"] and v["smoothing_s"] > 0,
             "%s: the pipeline smooths the mesh: min angle %.2f -> %.2f" % (r["case"], v["min_angle_delaunay"], v["min_angle_smoothed"]))

# Stage 5's benchmark: EC ratio and the seed-aware mesh against Canny's, on the bundled cases.
script = os.path.join(ft.fm.ROOT, "scripts", "benchmark_rsp.py")
run = subprocess.run([shutil.which("pvpython"), script, "--no-slic", "--out", out + "_rsp"], env=env, capture_output=True,
                     text=True)
print(run.stdout[-2000:])
ft.check(run.returncode == 0, "benchmark_rsp.py exits 0 (stderr: %s)" % run.stderr[-500:])
rows = list(csv.DictReader(open(out + "_rsp.csv"))) if os.path.isfile(out + "_rsp.csv") else []
ft.check(sorted(r["case"] for r in rows) == ["liver-ct-totalseg", "nuclei-dsb2018"], "benchmark_rsp: both bundled cases")
for r in rows:
    v = {k: float(x) for k, x in r.items() if k != "case"}
    ft.check(v["ec_ratio"] > 1.0 and v["rsp_s"] > 0, "%s: EC ratio %.2f > 1" % (r["case"], v["ec_ratio"]))
    for mesh in ("canny", "rsp"):
        ft.check(0 < v["dice_elements_" + mesh] <= v["oracle_" + mesh] + 1e-9 <= 1.0 + 1e-9 and v["dice_" + mesh] > 0,
                 "%s: %s mesh: the elements' Dice %.3f <= oracle %.3f (label image %.3f)" % (
                     r["case"], mesh, v["dice_elements_" + mesh], v["oracle_" + mesh], v["dice_" + mesh]))

# The kept re-cut's benchmark: the bundled object case and the bundled labelled case, each edit's
# cut timed with its parts inside it.
script = os.path.join(ft.fm.ROOT, "scripts", "benchmark_recut.py")
run = subprocess.run([shutil.which("pvpython"), script, "--edits", "2", "--out", out + "_recut"], env=env,
                     capture_output=True, text=True)
print(run.stdout[-1500:])
ft.check(run.returncode == 0, "benchmark_recut.py exits 0 (stderr: %s)" % run.stderr[-500:])
rows = list(csv.DictReader(open(out + "_recut.csv"))) if os.path.isfile(out + "_recut.csv") else []
ft.check(sorted({(r["case"], r["labels"]) for r in rows}) == [("abdomen-ct-totalseg", "6"), ("liver-ct-totalseg", "2")],
         "benchmark_recut: the liver (2 labels) and the abdomen (6)")
for case in ("liver-ct-totalseg", "abdomen-ct-totalseg"):
    for edit in ("add", "remove"):
        part = {r["part"]: float(r["median_s"]) for r in rows if r["case"] == case and r["edit"] == edit}
        solve = "FlowSeconds" if case.startswith("liver") else "ExpansionSeconds"
        ft.check(part.get("CutTotalSeconds", 0) > 0 and all(part.get(p, -1) >= 0 for p in ("SetupSeconds", "GeodesicSeconds", solve)) and
                 part["SetupSeconds"] + part[solve] <= part["CutTotalSeconds"] + 1e-9,
                 "%s, %s a seed: the cut %.3f s holds its parts" % (case, edit, part.get("CutTotalSeconds", 0)))
ft.finish("benchmark")
