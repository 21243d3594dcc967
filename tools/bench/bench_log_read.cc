// bench_log_read: the time to read whole logs through io::BagReader (open,
// decode every IMU sample, scan and ground-truth pose in stamp order), for
// comparing the formats of the same flight (issue: an MCAP log read at least
// as fast as the ROS1 bag). Each set of files is read --repeats times; the
// report is the fastest pass (the others warm the page cache), in wall time
// and in this process's CPU time (user + system: on a machine shared with
// other work the wall time also counts the time other processes held the
// core).
//
//   bench_log_read --repeats=5 ros1/uav1.bag,ros1/uav2.bag,ros1/uav3.bag
//                  mcap/uav1.mcap,mcap/uav2.mcap,mcap/uav3.mcap   (one line)
#include <gflags/gflags.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "swarmlio/common/split_list.h"
#include "swarmlio/io/bag_reader.h"

DEFINE_int32(repeats, 5, "passes over each set of files (the fastest is reported)");

namespace {

// Reads every file of `files` once; false (printed) on an error.
bool ReadOnce(const std::vector<std::string>& files, int64_t* records) {
  *records = 0;
  for (const std::string& path : files) {
    std::unique_ptr<swarmlio::io::BagReader> reader;
    swarmlio::Status status = swarmlio::io::BagReader::Open(path, {}, &reader);
    swarmlio::io::BagRecord record;
    bool has_record = true;
    while (status.ok() && has_record) {
      status = reader->Next(&record, &has_record);
      if (has_record) ++*records;
    }
    if (!status.ok()) {
      std::fprintf(stderr, "error: %s\n", status.message().c_str());
      return false;
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage("bench_log_read [--repeats=N] FILE[,FILE...] [FILE[,FILE...] ...]");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  if (argc < 2 || FLAGS_repeats < 1) {
    std::fprintf(stderr, "usage: %s\n", gflags::ProgramUsage());
    return 2;
  }
  std::printf(
      "| files | records | fastest pass [s] | records/s | fastest pass CPU [s] |\n"
      "|---|---|---|---|---|\n");
  for (int k = 1; k < argc; ++k) {
    const std::vector<std::string> files = swarmlio::SplitList(argv[k]);
    double best_s = 1e300;
    double best_cpu_s = 1e300;
    int64_t records = 0;
    for (int pass = 0; pass < FLAGS_repeats; ++pass) {
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpu_start = std::clock();
      if (!ReadOnce(files, &records)) return 1;
      const double cpu_s = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
      const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
      best_s = std::min(best_s, elapsed.count());
      best_cpu_s = std::min(best_cpu_s, cpu_s);
    }
    std::printf("| %s | %lld | %.3f | %.0f | %.3f |\n", argv[k], static_cast<long long>(records),
                best_s, static_cast<double>(records) / best_s, best_cpu_s);
  }
  return 0;
}
