#include "swarmlio/teammate/association.h"

#include <algorithm>
#include <tuple>

namespace swarmlio::teammate {

std::vector<int> AssociateNearest(const std::vector<Eigen::Vector3d>& predictions,
                                  const std::vector<Eigen::Vector3d>& clusters, double gate_m,
                                  std::vector<bool>* available) {
  std::vector<int> assignment(predictions.size(), -1);
  std::vector<std::tuple<double, int, int>> pairs;  // (distance^2, prediction, cluster)
  const double gate2 = gate_m * gate_m;
  for (size_t t = 0; t < predictions.size(); ++t) {
    for (size_t c = 0; c < clusters.size(); ++c) {
      if (!(*available)[c]) continue;
      const double d2 = (predictions[t] - clusters[c]).squaredNorm();
      if (d2 <= gate2) pairs.emplace_back(d2, static_cast<int>(t), static_cast<int>(c));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [d2, t, c] : pairs) {
    if (assignment[static_cast<size_t>(t)] >= 0 || !(*available)[static_cast<size_t>(c)]) continue;
    assignment[static_cast<size_t>(t)] = c;
    (*available)[static_cast<size_t>(c)] = false;
  }
  return assignment;
}

}  // namespace swarmlio::teammate
