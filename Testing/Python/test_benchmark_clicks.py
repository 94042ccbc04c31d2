"""The interactive-loop benchmark on the bundled cases, two rounds: a row per method, case and round;
every seed the robot adds keeps its label in the cuts' results, and no round of the cuts lowers
Dice by more than 0.05."""
import csv
import os
import shutil
import subprocess

import fmtest as ft

out = os.path.join(ft.scratch(), "clicks")
script = os.path.join(ft.fm.ROOT, "scripts", "benchmark_clicks.py")
run = subprocess.run([shutil.which("pvpython"), script, "--cases", "nuclei-dsb2018,liver-ct-totalseg", "--rounds", "2",
                      "--out", out], capture_output=True, text=True)
print(run.stdout[-3000:])
ft.check(run.returncode == 0, "benchmark_clicks.py exits 0 (stderr: %s)" % run.stderr[-500:])
rows = list(csv.DictReader(open(out + ".csv"))) if os.path.isfile(out + ".csv") else []
methods = ("supervoxel", "voxel", "random_walker", "watershed")
for case, task in (("nuclei-dsb2018", "class"), ("liver-ct-totalseg", "object")):
    for method in methods:
        mine = [r for r in rows if r["case"] == case and r["method"] == method]
        ft.check(len(mine) == 3 and all(r["task"] == task for r in mine), "%s %s: three rounds with task %s" % (case, method, task))
        if method in ("supervoxel", "voxel") and mine:
            dice = [float(r["dice"]) for r in mine]
            ft.check(int(mine[0]["lost_seeds"]) == 0, "%s %s: every added seed keeps its label" % (case, method))
            ft.check(all(dice[k] - dice[k + 1] <= 0.05 for k in range(len(dice) - 1)),
                     "%s %s: no round lowers Dice by more than 0.05 (%s)" % (case, method, dice))
            ft.check(0.0 < float(mine[0]["round_s"]) < 60, "%s %s: a round's seconds are sane" % (case, method))
ft.check(os.path.isfile(out + ".md") and "NoC@90" in open(out + ".md").read(), "the Markdown table has NoC@90")
ft.finish()
