#!/usr/bin/env bash
# The main job: set up, then segment the bundled 2D and 3D cases into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# The task as the user would give it: every nucleus like the seeded ones; the one liver.
for c in nuclei-dsb2018:class liver-ct-totalseg:object; do
  task=${c#*:}
  c=${c%:*}
  xvfb-run -a pvpython scripts/featuremesh_segment.py "Data/$c/image.mha" --task "$task" \
    --object-seeds "Data/$c/seeds_object.csv" --background-seeds "Data/$c/seeds_background.csv" \
    --truth "Data/$c/truth.mha" --out out
done
# Several labels: five organs of the abdomen CT from one CSV of labelled seeds (x,y,z,label).
c=Data/multilabel/abdomen-ct-totalseg
xvfb-run -a pvpython scripts/featuremesh_segment.py "$c/image.mha" --seeds "$c/seeds.csv" --labels "$c/labels.csv" \
  --truth "$c/truth.mha" --out out
