// The long-run figures of the clock synchronisation (docs/network.md §9):
// the offset error of every pair of three drones with offset and drifting
// clocks, on a simulated link, checked once per second, over several seeds.
//
//   swarmlio_clock_sync_figures                      # the table of docs/network.md
//   swarmlio_clock_sync_figures --jitter_ms 1 --reorder 0.2 --seeds 10 --end_s 10,30,60
//
// About 20 s for the default table on one core.
#include <gflags/gflags.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "swarmlio/net/clock_sync_simulation.h"

DEFINE_double(latency_ms, 200.0, "mean one-way latency of every link [ms]");
DEFINE_double(jitter_ms, 20.0, "normal jitter (1 sigma) of every link [ms]");
DEFINE_double(loss, 0.3, "loss probability of every packet");
DEFINE_double(reorder, 0.0, "probability that a packet is held back U(0, --reorder_ms)");
DEFINE_double(reorder_ms, 50.0, "longest hold-back of a reordered packet [ms]");
DEFINE_string(exchange, "requests", "requests (TimeSync at 1 Hz) or state_echo (10 Hz states)");
DEFINE_string(end_s, "60,300,900,1800", "comma-separated run lengths [s]; the error is taken at the end");
DEFINE_int32(seeds, 5, "seeds 1..N per run length");

namespace {

using swarmlio::Status;
namespace net = swarmlio::net;

bool ParseLengths(const std::string& text, std::vector<int>* lengths) {
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long value = std::strtol(item.c_str(), &end, 10);
    if (end == item.c_str() || *end != '\0' || value <= 0) return false;
    lengths->push_back(static_cast<int>(value));
  }
  return !lengths->empty();
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage("clock synchronisation figures on a simulated network");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  std::vector<int> lengths;
  if (!ParseLengths(FLAGS_end_s, &lengths) || FLAGS_seeds < 1) {
    std::fprintf(stderr, "error: --end_s must list positive seconds (e.g. 60,300) and --seeds >= 1\n");
    return 2;
  }
  net::ClockSyncOptions options;
  if (FLAGS_exchange == "requests") {
    options.exchange = net::ClockExchange::kRequests;
  } else if (FLAGS_exchange != "state_echo") {
    std::fprintf(stderr, "error: --exchange is requests or state_echo, not '%s'\n",
                 FLAGS_exchange.c_str());
    return 2;
  }
  net::LinkOptions link;
  link.latency_mean_s = 1e-3 * FLAGS_latency_ms;
  link.jitter_std_s = 1e-3 * FLAGS_jitter_ms;
  link.loss_probability = FLAGS_loss;
  link.reorder_probability = FLAGS_reorder;
  link.reorder_delay_max_s = 1e-3 * FLAGS_reorder_ms;
  std::printf("%s, %.0f ms +- %.0f ms, %.0f %% loss, %.0f %% held back, %d seeds\n",
              FLAGS_exchange.c_str(), FLAGS_latency_ms, FLAGS_jitter_ms, 100.0 * FLAGS_loss,
              100.0 * FLAGS_reorder, FLAGS_seeds);
  std::printf("%8s %12s %12s %14s\n", "at [s]", "max [ms]", "rms [ms]", "|e|<=3std [%]");
  for (int end_s : lengths) {
    net::ClockSyncFigures f;
    const Status s = net::RunClockSyncCase(link, options, FLAGS_seeds, end_s, end_s,
                                           net::SwarmClocks(), &f);
    if (!s.ok()) {
      std::fprintf(stderr, "error: %s\n", s.message().c_str());
      return 1;
    }
    std::printf("%8d %12.3f %12.3f %14.1f\n", end_s, f.max_abs_ms, f.rms_ms, 100.0 * f.within_3_sigma);
  }
  return 0;
}
