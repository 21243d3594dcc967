#!/usr/bin/env bash
# Regenerates docs/results_scenarios.md and the headline of docs/results.md:
# the scenarios sweep (configs/sweeps/scenarios.yaml: every scenario x its
# file seed plus the held-out offsets x {swarm, single-agent}) through GNU
# parallel on every core, then its report (tools/sweep/scenarios_report.sh).
# The same as
#
#   tools/sweep.sh local configs/sweeps/scenarios.yaml [OUT]
#
# (docs/sweeps.md). Re-running it skips the finished runs. Other grids (other
# scenarios, seeds, an imperfections map, estimator variants) are sweep files
# of their own; the former environment knobs are keys there:
#   SEED_OFFSETS -> sweep.seed_offsets, scenario names -> sweep.scenarios,
#   IMPERFECTIONS / IMPERFECTIONS_YAML -> variants[].imperfections,
#   SINGLE_AGENT=0 -> sweep.modes: [swarm], DOC / RESULTS_DOC / HEADLINE -> the
#   report's environment (tools/sweep/scenarios_report.sh).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
for knob in SEED_OFFSETS IMPERFECTIONS IMPERFECTIONS_YAML SINGLE_AGENT; do
  if [[ -n "${!knob:-}" ]]; then
    echo "$knob is now a key of a sweep file (see the head of $0 and docs/sweeps.md)" >&2
    exit 2
  fi
done
if [[ $# -gt 0 ]]; then
  echo "scenario names are now sweep.scenarios of a sweep file (docs/sweeps.md)" >&2
  exit 2
fi
exec bash "$ROOT/tools/sweep.sh" local "$ROOT/configs/sweeps/scenarios.yaml" \
  "${OUT:-$ROOT/results/sweeps/scenarios}"
