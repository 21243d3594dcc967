// swarmlio_net_proxy: a lossy UDP relay for fault runs of the live swarm on one
// machine (docs/online.md "Faults"). Each route listens on one port and forwards
// every datagram to another, after dropping it with --loss, delaying it by
// --delay_s + N(0, --jitter_s) (truncated at 0) and, with --reorder_probability,
// by an extra U(0, --reorder_delay_max_s), so later datagrams overtake it;
// with --skip_delay_probability a datagram skips --delay_s (netem's "reorder":
// sent at once, overtaking the delayed ones). In
// unicast mode the drones' peer tables name the proxy's ports instead of the
// teammates' own:
//
//   swarmlio_net_proxy --routes 9201=9101,9202=9102,9203=9103 --loss 0.3 --delay_s 0.2
//   swarmlio_live ... --port 9101 --peers uav1=127.0.0.1:9201,uav2=127.0.0.1:9202,...
//
// Why a proxy: the kernel's netem qdisc would do this per interface, but it needs
// CAP_NET_ADMIN and the sch_netem module, which the CI machine does not have
// ("Specified qdisc kind is unknown"), and Debian packages no user-space UDP
// impairment relay. Datagrams are relayed byte for byte; the drones authenticate
// them, so the proxy can drop, delay and reorder but not forge. Runs until
// SIGINT/SIGTERM or --duration_s, then prints its counters.
#include <arpa/inet.h>
#include <gflags/gflags.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <queue>
#include <random>
#include <string>
#include <vector>

DEFINE_string(routes, "", "listen_port=forward_port,... (127.0.0.1)");
DEFINE_double(loss, 0.0, "probability that a datagram is dropped, [0, 1]");
DEFINE_double(delay_s, 0.0, "mean one-way delay added [s]");
DEFINE_double(jitter_s, 0.0, "std of the delay [s] (truncated at 0)");
DEFINE_double(reorder_probability, 0.0, "probability of an extra delay U(0, reorder_delay_max_s)");
DEFINE_double(reorder_delay_max_s, 0.05, "largest extra delay of a reordered datagram [s]");
DEFINE_double(skip_delay_probability, 0.0,
              "probability that a datagram skips --delay_s (netem's reorder)");
DEFINE_double(duration_s, 0.0, "exit after this long (0: until SIGINT/SIGTERM) [s]");
DEFINE_uint64(seed, 1, "random seed");

namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

struct Route {
  int listen_port = 0;
  int forward_port = 0;
  int fd = -1;
  sockaddr_in destination{};
  uint64_t received = 0, dropped = 0, forwarded = 0, reordered = 0, skipped = 0, send_errors = 0;
};

struct Pending {
  int64_t due_ns;
  uint64_t order;
  size_t route;
  std::vector<uint8_t> bytes;
  bool operator>(const Pending& o) const {
    return due_ns != o.due_ns ? due_ns > o.due_ns : order > o.order;
  }
};

int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool ParseRoutes(const std::string& text, std::vector<Route>* routes) {
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    const size_t eq = item.find('=');
    if (eq == std::string::npos) return false;
    Route r;
    try {
      r.listen_port = std::stoi(item.substr(0, eq));
      r.forward_port = std::stoi(item.substr(eq + 1));
    } catch (const std::exception&) {
      return false;
    }
    if (r.listen_port <= 0 || r.listen_port > 65535 || r.forward_port <= 0 ||
        r.forward_port > 65535) {
      return false;
    }
    routes->push_back(r);
    start = end + 1;
  }
  return !routes->empty();
}

int Usage(const char* message) {
  std::fprintf(stderr, "swarmlio_net_proxy: %s\n%s\n", message, gflags::ProgramUsage());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "lossy UDP relay for live-swarm fault runs\n"
      "  usage: swarmlio_net_proxy --routes LISTEN=FORWARD,... [--loss P --delay_s D ...]");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  std::vector<Route> routes;
  if (!ParseRoutes(FLAGS_routes, &routes)) return Usage("--routes must be port=port,...");
  if (!(FLAGS_loss >= 0.0 && FLAGS_loss <= 1.0) ||
      !(FLAGS_reorder_probability >= 0.0 && FLAGS_reorder_probability <= 1.0) ||
      !(FLAGS_skip_delay_probability >= 0.0 && FLAGS_skip_delay_probability <= 1.0)) {
    return Usage("--loss, --reorder_probability and --skip_delay_probability must be in [0, 1]");
  }
  if (!(FLAGS_delay_s >= 0.0 && FLAGS_jitter_s >= 0.0 && FLAGS_reorder_delay_max_s >= 0.0 &&
        FLAGS_duration_s >= 0.0)) {
    return Usage("delays and durations must be >= 0");
  }
  for (Route& r : routes) {
    r.fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    if (r.fd < 0) {
      std::fprintf(stderr, "socket: %s\n", std::strerror(errno));
      return 1;
    }
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = htons(static_cast<uint16_t>(r.listen_port));
    if (bind(r.fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
      std::fprintf(stderr, "bind 127.0.0.1:%d: %s\n", r.listen_port, std::strerror(errno));
      return 1;
    }
    r.destination.sin_family = AF_INET;
    r.destination.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    r.destination.sin_port = htons(static_cast<uint16_t>(r.forward_port));
  }
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);

  std::mt19937_64 rng(FLAGS_seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::priority_queue<Pending, std::vector<Pending>, std::greater<Pending>> queue;
  uint64_t order = 0;
  const int64_t start_ns = NowNs();
  std::vector<pollfd> fds;
  for (const Route& r : routes) fds.push_back({r.fd, POLLIN, 0});
  std::vector<uint8_t> buffer(65536);
  while (!g_stop) {
    const int64_t now = NowNs();
    if (FLAGS_duration_s > 0.0 && now - start_ns >= static_cast<int64_t>(FLAGS_duration_s * 1e9)) {
      break;
    }
    while (!queue.empty() && queue.top().due_ns <= now) {
      const Pending& p = queue.top();
      Route& r = routes[p.route];
      if (sendto(r.fd, p.bytes.data(), p.bytes.size(), 0,
                 reinterpret_cast<const sockaddr*>(&r.destination), sizeof(r.destination)) < 0) {
        ++r.send_errors;  // the drone is not listening (killed): the datagram is lost
      } else {
        ++r.forwarded;
      }
      queue.pop();
    }
    int timeout_ms = 5;
    if (!queue.empty()) {
      const int64_t wait_ns = queue.top().due_ns - NowNs();
      timeout_ms = wait_ns <= 0 ? 0 : static_cast<int>(std::min<int64_t>(5, wait_ns / 1000000 + 1));
    }
    if (poll(fds.data(), fds.size(), timeout_ms) < 0 && errno != EINTR) {
      std::fprintf(stderr, "poll: %s\n", std::strerror(errno));
      return 1;
    }
    for (size_t i = 0; i < routes.size(); ++i) {
      if ((fds[i].revents & POLLIN) == 0) continue;
      for (;;) {
        const ssize_t n = recv(routes[i].fd, buffer.data(), buffer.size(), 0);
        if (n < 0) break;  // EAGAIN: drained
        Route& r = routes[i];
        ++r.received;
        if (uniform(rng) < FLAGS_loss) {
          ++r.dropped;
          continue;
        }
        const bool skip = FLAGS_skip_delay_probability > 0.0 &&
                          uniform(rng) < FLAGS_skip_delay_probability;
        double delay = (skip ? 0.0 : FLAGS_delay_s) + FLAGS_jitter_s * normal(rng);
        if (delay < 0.0) delay = 0.0;
        if (skip) ++r.skipped;
        if (FLAGS_reorder_probability > 0.0 && uniform(rng) < FLAGS_reorder_probability) {
          delay += FLAGS_reorder_delay_max_s * uniform(rng);
          ++r.reordered;
        }
        queue.push({NowNs() + static_cast<int64_t>(delay * 1e9), order++, i,
                    std::vector<uint8_t>(buffer.begin(), buffer.begin() + n)});
      }
    }
  }
  std::printf("swarmlio_net_proxy: %.1f s, loss %.2f, delay %.3f s, jitter %.3f s, reorder %.2f, "
              "skip delay %.2f\n",
              1e-9 * static_cast<double>(NowNs() - start_ns), FLAGS_loss, FLAGS_delay_s,
              FLAGS_jitter_s, FLAGS_reorder_probability, FLAGS_skip_delay_probability);
  for (const Route& r : routes) {
    std::printf("  %d -> %d: received %llu, dropped %llu, forwarded %llu (extra-delayed %llu, "
                "skipped the delay %llu), undeliverable %llu\n",
                r.listen_port, r.forward_port, static_cast<unsigned long long>(r.received),
                static_cast<unsigned long long>(r.dropped),
                static_cast<unsigned long long>(r.forwarded),
                static_cast<unsigned long long>(r.reordered),
                static_cast<unsigned long long>(r.skipped),
                static_cast<unsigned long long>(r.send_errors));
    close(r.fd);
  }
  return 0;
}
