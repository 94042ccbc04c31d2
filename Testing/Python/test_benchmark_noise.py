"""The noise benchmark on the bundled liver, clean and with noise of 0.1 of its intensity range: the
table has both floors per level, the estimated noise follows the added noise, and with the floor
the noisy liver keeps about the clean liver's nodes while the thesis's thresholds (floor off) give
it more."""
import csv
import os
import shutil
import subprocess

import fmtest as ft

out = os.path.join(ft.scratch(), "noise")
script = os.path.join(ft.fm.ROOT, "scripts", "benchmark_noise.py")
run = subprocess.run([shutil.which("pvpython"), script, "--cases", "liver-ct-totalseg", "--levels", "0,0.1", "--out", out],
                     capture_output=True, text=True)
print(run.stdout[-2500:])
ft.check(run.returncode == 0, "benchmark_noise.py exits 0 (stderr: %s)" % run.stderr[-500:])
rows = list(csv.DictReader(open(out + ".csv"))) if os.path.isfile(out + ".csv") else []
ft.check([(r["level"], r["floor"]) for r in rows] == [("0.0", "1"), ("0.0", "0"), ("0.1", "1"), ("0.1", "0")],
         "a row per level and floor")
if len(rows) == 4:
    clean, _, noisy, thesis = ({k: float(v) for k, v in r.items() if k != "case"} for r in rows)
    # The liver CT has noise of its own (about 13 HU): the estimate combines both.
    expected = (noisy["noise_sigma"] ** 2 + clean["estimated_sigma"] ** 2) ** 0.5
    ft.check(abs(noisy["estimated_sigma"] - expected) <= 0.1 * expected,
             "estimated noise %.1f for %.1f added to %.1f" % (noisy["estimated_sigma"], noisy["noise_sigma"], clean["estimated_sigma"]))
    ft.check(noisy["nodes"] <= 1.3 * clean["nodes"], "with the floor, %d nodes noisy against %d clean" % (noisy["nodes"], clean["nodes"]))
    ft.check(thesis["nodes"] > 1.2 * noisy["nodes"], "without it, %d nodes" % thesis["nodes"])
    ft.check(all(0.0 <= r["dice_supervoxel"] <= 1.0 and r["elements"] > r["nodes"] for r in (clean, noisy, thesis)),
             "Dice and element counts are sane")
ft.finish()
