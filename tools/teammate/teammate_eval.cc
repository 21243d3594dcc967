// swarmlio_teammate_eval: runs the teammate detector on every drone of a
// simulated scenario, with true ego poses as input, and prints the
// acceptance figures of docs/teammate.md: identification time and initial
// T_Gi_Gj error per drone pair, observation accuracy, temporary trackers on
// decoys, false identifications and observations, processing time.
//
//   swarmlio_teammate_eval --scenario=configs/scenarios/indoor_3uav.yaml
//   swarmlio_teammate_eval --scenario=configs/scenarios/decoys.yaml --config=my.yaml
//
// Exit code 0 when every check passes, 1 on failure, 2 on bad usage.
#include <gflags/gflags.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "sim_harness.h"
#include "swarmlio/config/config_file.h"
#include "swarmlio/sim/scenario.h"

DEFINE_string(scenario, "", "scenario YAML file (configs/scenarios/*.yaml)");
DEFINE_string(config, "", "optional YAML file with a `teammate:` section (detector options)");
DEFINE_double(duration_s, 0.0, "override the scenario duration when > 0");
DEFINE_int32(threads, 2, "observers simulated in parallel");
DEFINE_double(drop_probability, 0.1, "fraction of lost broadcast messages");
DEFINE_double(latency_s, 0.02, "broadcast delivery delay [s]");
DEFINE_double(max_identification_s, 10.0,
              "check: every pair identified within this time after the excitation start");
DEFINE_double(max_translation_error_m, 0.1, "check: initial T_Gi_Gj translation error");
DEFINE_double(max_rotation_error_deg, 2.0, "check: initial T_Gi_Gj rotation error");
DEFINE_double(max_median_observation_error_m, 0.05, "check: median observation error at 2-10 m");
DEFINE_bool(verbose, false, "print tracker and matching events per scan (use --threads=1)");
DEFINE_bool(require_all_pairs, true, "check that every ordered drone pair is identified");

namespace swarmlio::teammate {
namespace {

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(std::floor(q * (v.size() - 1) + 0.5)));
  return v[k];
}

int Main() {
  if (FLAGS_scenario.empty()) {
    std::fprintf(stderr, "usage: swarmlio_teammate_eval --scenario=FILE [--config=FILE]\n");
    return 2;
  }
  sim::Scenario scenario;
  Status status = sim::LoadScenario(FLAGS_scenario, &scenario);
  if (!status.ok()) {
    std::fprintf(stderr, "error: %s\n", status.message().c_str());
    return 1;
  }
  if (FLAGS_duration_s > 0) scenario.options.duration_s = FLAGS_duration_s;
  TeammateDetectorOptions options;
  if (!FLAGS_config.empty()) {
    config::ConfigFile file;
    status = config::ConfigFile::Load(FLAGS_config, &file);
    if (status.ok()) status = file.Read("teammate", &options);
    if (!status.ok()) {
      std::fprintf(stderr, "error: %s\n", status.message().c_str());
      return 1;
    }
  }
  harness::HarnessOptions harness_options;
  harness_options.drop_probability = FLAGS_drop_probability;
  harness_options.latency_s = FLAGS_latency_s;

  const std::string name = scenario.options.name;
  const sim::Simulator sim(std::move(scenario.scene), scenario.drones, scenario.objects,
                           scenario.simulation_config());
  const int n = static_cast<int>(sim.drones().size());
  std::vector<harness::ObserverReport> reports(static_cast<size_t>(n));
  std::vector<Status> results(static_cast<size_t>(n));
  std::atomic<int> next{0};
  auto verbose = [&](const harness::PreparedScan& scan, const ScanResult& result) {
    for (const TrackerState& s : result.trackers) {
      if (!s.created) continue;
      std::printf("[%s t=%.2f] tracker %d started at G_i (%.2f %.2f %.2f)%s\n",
                  sim.drones()[scan.observer].name.c_str(), scan.t_true_s, s.tracker_id,
                  s.p_in_Gi.x(), s.p_in_Gi.y(), s.p_in_Gi.z(), s.drone_id >= 0 ? " (identified)" : "");
    }
    for (const MatchAttempt& a : result.match_attempts) {
      std::printf("[%s t=%.2f] match tracker %d (%d positions, sv2 %.3f m^2):", sim.drones()[scan.observer].name.c_str(),
                  scan.t_true_s, a.tracker_id, a.trajectory_size, a.second_singular_value_m2);
      for (const MatchCandidate& c : a.candidates) {
        std::printf(" [%d: %s res %.3f pairs %d]", c.drone_id, c.valid ? "ok" : "invalid",
                    c.match.mean_residual_m, c.match.num_pairs);
      }
      std::printf("%s\n", a.accepted >= 0 ? " ACCEPTED" : "");
    }
  };
  auto worker = [&] {
    for (int i = next++; i < n; i = next++) {
      results[static_cast<size_t>(i)] = harness::EvaluateObserver(
          sim, i, options, harness_options, &reports[static_cast<size_t>(i)],
          FLAGS_verbose ? harness::ResultCallback(verbose) : harness::ResultCallback());
    }
  };
  std::vector<std::thread> threads;
  for (int k = 1; k < std::max(1, FLAGS_threads); ++k) threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < n; ++i) {
    if (!results[static_cast<size_t>(i)].ok()) {
      std::fprintf(stderr, "error: observer %d: %s\n", i, results[static_cast<size_t>(i)].message().c_str());
      return 1;
    }
  }

  bool pass = true;
  std::printf("scenario %s: %d drones, %.1f s, broadcast loss %.0f %%, latency %.0f ms\n",
              name.c_str(), n, sim.config().duration_s, 100 * FLAGS_drop_probability,
              1e3 * FLAGS_latency_s);
  std::printf("excitation start (true time):");
  for (int j = 0; j < n; ++j) std::printf(" %s %.2f s", sim.drones()[j].name.c_str(), harness::ExcitationStartTime(sim, j));
  std::printf("\n\nidentifications (observer -> teammate):\n");
  std::printf("  %-6s %-6s %8s %10s %10s %9s %9s %9s %9s %9s %6s %s\n", "obs", "mate", "t [s]", "since_exc", "since_vis",
              "dT [m]", "dR [deg]", "dyaw[deg]", "res [m]", "2nd [m]", "pairs", "correct");
  int false_identifications = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      const harness::IdentificationRecord* found = nullptr;
      for (const auto& r : reports[static_cast<size_t>(i)].identifications) {
        if (r.teammate == j && found == nullptr) found = &r;
      }
      if (found == nullptr) {
        std::printf("  %-6s %-6s   NOT IDENTIFIED\n", sim.drones()[i].name.c_str(), sim.drones()[j].name.c_str());
        if (FLAGS_require_all_pairs) pass = false;
        continue;
      }
      const auto& r = *found;
      std::printf("  %-6s %-6s %8.2f %10.2f %10.2f %9.4f %9.3f %+9.3f %9.4f %9.3f %6d %s\n",
                  sim.drones()[i].name.c_str(), sim.drones()[j].name.c_str(), r.t_true_s,
                  r.since_excitation_s, r.since_visible_s, r.translation_error_m, r.rotation_error_deg,
                  r.yaw_error_deg, r.mean_residual_m, r.second_best_residual_m, r.num_pairs, r.correct ? "yes" : "NO");
      if (r.since_excitation_s > FLAGS_max_identification_s ||
          r.translation_error_m > FLAGS_max_translation_error_m ||
          r.rotation_error_deg > FLAGS_max_rotation_error_deg) {
        pass = false;
      }
    }
    for (const auto& r : reports[static_cast<size_t>(i)].identifications) {
      if (!r.correct) ++false_identifications;
    }
  }

  std::printf("\nobservations ^{bi}p_{bj} while tracked:\n");
  std::vector<double> all_2_10;
  int wrong = 0, total = 0, temp_mates = 0, temp_else = 0;
  std::vector<double> process_ms;
  int64_t points = 0;
  int scans = 0;
  for (int i = 0; i < n; ++i) {
    const auto& rep = reports[static_cast<size_t>(i)];
    wrong += rep.wrong_observations;
    total += static_cast<int>(rep.observations.size());
    temp_mates += rep.temporary_on_teammates;
    temp_else += rep.temporary_elsewhere;
    process_ms.insert(process_ms.end(), rep.process_ms.begin(), rep.process_ms.end());
    points += rep.points;
    scans += rep.scans;
    for (int j = 0; j < n; ++j) {
      if (i == j) continue;
      const harness::VisibilityRecord& vis = rep.visibility[static_cast<size_t>(j)];
      std::printf("  %-6s -> %-6s visible in %d of %d scans (%d with tape), first with tape after the "
                  "excitation start at %.2f s\n",
                  sim.drones()[i].name.c_str(), sim.drones()[j].name.c_str(), vis.scans_with_points,
                  rep.scans, vis.scans_with_tape, vis.first_tape_s);
      std::vector<double> e, e_2_10, along, vertical;
      for (const auto& o : rep.observations) {
        if (o.teammate != j) continue;
        e.push_back(o.error_m);
        along.push_back(o.along_error_m);
        vertical.push_back(o.vertical_error_m);
        if (o.range_m >= 2.0 && o.range_m <= 10.0) e_2_10.push_back(o.error_m);
      }
      all_2_10.insert(all_2_10.end(), e_2_10.begin(), e_2_10.end());
      std::printf("  %-6s -> %-6s %5zu obs, median %.4f m, p90 %.4f m, max %.4f m; at 2-10 m: %5zu, median %.4f m\n",
                  sim.drones()[i].name.c_str(), sim.drones()[j].name.c_str(), e.size(),
                  Quantile(e, 0.5), Quantile(e, 0.9), e.empty() ? 0.0 : *std::max_element(e.begin(), e.end()),
                  e_2_10.size(), Quantile(e_2_10, 0.5));
      std::printf("      error along the line of sight: median %+.4f m (p10 %+.4f, p90 %+.4f); vertical: median %+.4f m (p10 %+.4f, p90 %+.4f)\n",
                  Quantile(along, 0.5), Quantile(along, 0.1), Quantile(along, 0.9),
                  Quantile(vertical, 0.5), Quantile(vertical, 0.1), Quantile(vertical, 0.9));
    }
  }
  const double median_2_10 = Quantile(all_2_10, 0.5);
  std::printf("  all pairs at 2-10 m: %zu obs, median %.4f m, p90 %.4f m\n", all_2_10.size(),
              median_2_10, Quantile(all_2_10, 0.9));
  if (!(median_2_10 <= FLAGS_max_median_observation_error_m)) pass = false;

  std::printf("\nfalse identifications: %d\n", false_identifications);
  std::printf("observations farther than 0.3 m from the drone they name: %d of %d\n", wrong, total);
  std::printf("temporary trackers started: %d on teammates, %d elsewhere (decoys, clutter) [",
              temp_mates, temp_else);
  for (int i = 0; i < n; ++i) {
    std::printf("%s%s %d/%d", i > 0 ? ", " : "", sim.drones()[i].name.c_str(),
                reports[static_cast<size_t>(i)].temporary_on_teammates,
                reports[static_cast<size_t>(i)].temporary_elsewhere);
  }
  std::printf("]\n");
  std::printf("ProcessScan wall time (informative; see bench_teammate): median %.3f ms, p90 %.3f ms, "
              "max %.3f ms over %d scans, %.0f points/scan\n",
              Quantile(process_ms, 0.5), Quantile(process_ms, 0.9),
              process_ms.empty() ? 0.0 : *std::max_element(process_ms.begin(), process_ms.end()),
              scans, scans > 0 ? static_cast<double>(points) / scans : 0.0);
  if (false_identifications > 0 || wrong > 0) pass = false;
  std::printf("\nRESULT: %s\n", pass ? "PASS" : "FAIL");
  return pass ? 0 : 1;
}

}  // namespace
}  // namespace swarmlio::teammate

int main(int argc, char** argv) {
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  return swarmlio::teammate::Main();
}
