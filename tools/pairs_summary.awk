# Aggregates swarm_pairs.csv files (swarmlio_replay's per-pair swarm metrics)
# into one line of numbers, for tools/run_scenarios.sh and
# tools/results_headline.sh:
#   identified total wrong latest_s ext_end_m ext_end_deg ext_max_m ext_max_deg
#   worst_rel_rmse_m fused_share worst_pair_share
# (the shares in [0, 1], -1 when no pair had the teammate in view).
#   awk -F, -f tools/pairs_summary.awk swarm_pairs.csv...
FNR == 1 { delete c; for (i = 1; i <= NF; ++i) c[$i] = i; next }
{
  total++
  if ($c["identified"] != 1) next
  ident++
  wrong += $c["wrong_identification"]
  if ($c["since_excitation_s"] > late) late = $c["since_excitation_s"]
  if ($c["extrinsic_end_m"] > em) em = $c["extrinsic_end_m"]
  if ($c["extrinsic_end_deg"] > ed) ed = $c["extrinsic_end_deg"]
  if ($c["extrinsic_max_m"] > xm) xm = $c["extrinsic_max_m"]
  if ($c["extrinsic_max_deg"] > xd) xd = $c["extrinsic_max_deg"]
  if ($c["relative_rmse_m"] > rel) rel = $c["relative_rmse_m"]
  v = $c["scans_in_view"]; f = $c["fused_in_view"]
  if (v > 0) { sv += v; sf += f; share = f / v; if (!np++ || share < worst) worst = share }
}
END {
  printf "%d %d %d %g %g %g %g %g %g %g %g\n", ident, total, wrong, late, em, ed, xm, xd, rel,
         np ? sf / sv : -1, np ? worst : -1
}
