#include "swarmlio/config/options_reader.h"

#include <algorithm>
#include <map>
#include <utility>

namespace swarmlio::config::internal {
namespace {

ReadError Error(const YamlNode& node, const std::string& key, std::string reason) {
  ReadError error;
  error.key = key;
  error.reason = std::move(reason);
  error.line = node.line();
  return error;
}

ReadError Expected(const YamlNode& node, const std::string& key, const std::string& what) {
  return Error(node, key, "expected " + what + ", got " + node.Describe());
}

std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string UnknownNameReason(const std::string& what,
                              const std::string& key,
                              const std::vector<std::string>& known) {
  std::string closest;
  std::size_t best = std::max<std::size_t>(2, key.size() / 3) + 1;
  for (const std::string& candidate : known) {
    const std::size_t d = EditDistance(key, candidate);
    if (d < best) {
      best = d;
      closest = candidate;
    }
  }
  std::string reason = "unknown " + what;
  if (!closest.empty()) reason += "; did you mean '" + closest + "'?";
  if (known.empty()) return reason + " (none are accepted here)";
  reason += " (valid " + what + "s: ";
  for (std::size_t i = 0; i < known.size(); ++i) reason += (i ? ", " : "") + known[i];
  return reason + ")";
}

namespace {

// Reads a sequence of exactly `n` numbers (any length when n < 0).
ReadError DecodeNumbers(const YamlNode& node,
                        const std::string& key,
                        int n,
                        const std::string& what,
                        std::vector<double>* values) {
  if (!node.IsSequence() || (n >= 0 && node.size() != static_cast<std::size_t>(n))) {
    return Expected(node, key, what);
  }
  std::vector<double> parsed(node.size());
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YamlNode element = node.Element(i);
    if (!element.AsDouble(&parsed[i])) {
      return Expected(element, IndexKey(key, i), "a number");
    }
  }
  *values = std::move(parsed);
  return {};
}

}  // namespace

std::string JoinKey(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

ReadError DecodeValue(const YamlNode& node, const std::string& key, bool* value) {
  if (!node.AsBool(value)) return Expected(node, key, "true or false");
  return {};
}

ReadError DecodeValue(const YamlNode& node, const std::string& key, double* value) {
  if (!node.AsDouble(value)) return Expected(node, key, "a number");
  return {};
}

ReadError DecodeValue(const YamlNode& node, const std::string& key, float* value) {
  double parsed = 0.0;
  if (!node.AsDouble(&parsed)) return Expected(node, key, "a number");
  *value = static_cast<float>(parsed);
  return {};
}

ReadError DecodeValue(const YamlNode& node, const std::string& key, std::string* value) {
  if (!node.IsScalar()) return Expected(node, key, "a string");
  *value = node.Scalar();
  return {};
}

ReadError DecodeValue(const YamlNode& node, const std::string& key, Eigen::Vector3d* value) {
  std::vector<double> v;
  ReadError error = DecodeNumbers(node, key, 3, "a sequence of 3 numbers [x, y, z]", &v);
  if (error.ok()) *value = Eigen::Vector3d(v[0], v[1], v[2]);
  return error;
}

ReadError DecodeValue(const YamlNode& node, const std::string& key, Eigen::Matrix3d* value) {
  std::vector<double> v;
  ReadError error =
      DecodeNumbers(node, key, 9, "a sequence of 9 numbers (3x3 matrix, row-major)", &v);
  if (error.ok()) {
    for (int i = 0; i < 9; ++i) (*value)(i / 3, i % 3) = v[static_cast<std::size_t>(i)];
  }
  return error;
}

ReadError DecodeValue(const YamlNode& node, const std::string& key, std::vector<double>* value) {
  return DecodeNumbers(node, key, -1, "a sequence of numbers", value);
}

ReadError DecodeValue(const YamlNode& node,
                      const std::string& key,
                      std::vector<std::string>* value) {
  if (!node.IsSequence()) return Expected(node, key, "a sequence of strings");
  std::vector<std::string> parsed(node.size());
  for (std::size_t i = 0; i < node.size(); ++i) {
    ReadError error = DecodeValue(node.Element(i), IndexKey(key, i), &parsed[i]);
    if (!error.ok()) return error;
  }
  *value = std::move(parsed);
  return {};
}

ReadError DecodeInteger(
    const YamlNode& node, const std::string& key, int64_t min, int64_t max, int64_t* value) {
  int64_t parsed = 0;
  if (!node.AsInt64(&parsed)) return Expected(node, key, "an integer");
  if (parsed < min || parsed > max) {
    return Error(node, key,
                 "value " + std::to_string(parsed) + " does not fit the field's integer type (" +
                     std::to_string(min) + " to " + std::to_string(max) + ")");
  }
  *value = parsed;
  return {};
}

ReadError UnknownEnumValue(const YamlNode& node,
                           const std::string& key,
                           const std::string& choices) {
  return Error(node, key, "unknown value " + node.Describe() + " (choices: " + choices + ")");
}

ReadError ExpectSection(const YamlNode& node, const std::string& key) {
  if (node.IsMap() || node.IsNull()) return {};
  return Expected(node, key, "a section (a map of key: value)");
}

ReadError ExpectList(const YamlNode& node, const std::string& key) {
  if (node.IsSequence() || node.IsNull()) return {};
  return Expected(node, key, "a list (a sequence of sections: - key: value)");
}

ReadError CheckKeys(const YamlNode& node,
                    const std::string& prefix,
                    const std::vector<std::string>& known,
                    const std::vector<GroupedKey>& grouped) {
  std::map<std::string, int> first_line;
  for (const YamlNode::Entry& entry : node.Entries()) {
    ReadError error;
    error.line = entry.line;
    if (!entry.key_is_scalar) {
      error.key = prefix;
      error.reason = "keys must be plain names, found a sequence or map used as a key";
      return error;
    }
    error.key = JoinKey(prefix, entry.key);
    const auto [it, inserted] = first_line.emplace(entry.key, entry.line);
    if (!inserted) {
      error.reason = "duplicate key (first set on line " + std::to_string(it->second) + ")";
      return error;
    }
    if (std::find(known.begin(), known.end(), entry.key) == known.end()) {
      for (const auto& [key, group] : grouped) {
        if (key != entry.key) continue;
        error.reason = "moved to " + JoinKey(JoinKey(prefix, group), key) + " (research and " +
                       "tuning keys live under '" + group + ":'; docs/configuration.md)";
        return error;
      }
      error.reason = UnknownNameReason("key", entry.key, known);
      return error;
    }
  }
  return {};
}

}  // namespace swarmlio::config::internal
