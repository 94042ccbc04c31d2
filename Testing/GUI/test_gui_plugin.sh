#!/usr/bin/env bash
# The README's GUI command, as written, with a fresh HOME (no remembered plugins):
#   paraview --plugin-search-paths=<plugin dir> --plugins=FeatureMesh
# usage: test_gui_plugin.sh PARAVIEW PLUGIN_DIR CHECK_SCRIPT WORK_DIR
set -u
paraview=$1 plugin_dir=$2 script=$3 work=$4
rm -rf "$work" && mkdir -p "$work/home"
export HOME="$work/home" FEATUREMESH_GUI_OUT="$work/result.txt"
timeout 240 "$paraview" --plugin-search-paths="$plugin_dir" --plugins=FeatureMesh --script="$script" > "$work/paraview.log" 2>&1
status=$?
[ -f "$FEATUREMESH_GUI_OUT" ] || { echo "FAIL: ParaView wrote no result (exit $status); log:"; tail -20 "$work/paraview.log"; exit 1; }
cat "$FEATUREMESH_GUI_OUT"
if grep -q '^FAIL' "$FEATUREMESH_GUI_OUT" || [ "$(grep -c '^ok' "$FEATUREMESH_GUI_OUT")" -lt 14 ]; then
  exit 1
fi
