// Maps a YAML map onto an options struct through its VisitFields().
//
// Implementation detail of ConfigFile::Read (config_file.h); use that. The
// template part only walks the fields; every YAML conversion lives in
// src/config/options_reader.cc behind non-template functions.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "swarmlio/config/option_fields.h"
#include "swarmlio/config/yaml_node.h"

namespace swarmlio::config::internal {

/// The first problem found while reading: full key path, reason and line.
struct ReadError {
  std::string key;     // e.g. "lidar.p_lidar_in_imu_m[1]"; "" for the root
  std::string reason;  // e.g. "expected a number, got 'abc'"
  int line = 0;        // 1-based, 0 when unknown
  bool ok() const { return reason.empty(); }
};

std::string JoinKey(const std::string& prefix, const std::string& key);
/// "unknown <what>; did you mean 'x'? (valid keys: ...)".
std::string UnknownNameReason(const std::string& what,
                              const std::string& name,
                              const std::vector<std::string>& known);

// Decoders for leaf types. Each leaves *value untouched on error.
ReadError DecodeValue(const YamlNode& node, const std::string& key, bool* value);
ReadError DecodeValue(const YamlNode& node, const std::string& key, double* value);
ReadError DecodeValue(const YamlNode& node, const std::string& key, float* value);
ReadError DecodeValue(const YamlNode& node, const std::string& key, std::string* value);
ReadError DecodeValue(const YamlNode& node, const std::string& key, Eigen::Vector3d* value);
ReadError DecodeValue(const YamlNode& node, const std::string& key, Eigen::Matrix3d* value);
ReadError DecodeValue(const YamlNode& node, const std::string& key, std::vector<double>* value);
ReadError DecodeValue(const YamlNode& node,
                      const std::string& key,
                      std::vector<std::string>* value);
ReadError DecodeInteger(
    const YamlNode& node, const std::string& key, int64_t min, int64_t max, int64_t* value);
ReadError UnknownEnumValue(const YamlNode& node,
                           const std::string& key,
                           const std::string& choices);
/// OK for a map or an empty value (an empty section keeps the defaults).
ReadError ExpectSection(const YamlNode& node, const std::string& key);
/// OK for a sequence or an empty value (an empty list keeps the field's value).
ReadError ExpectList(const YamlNode& node, const std::string& key);
/// Rejects duplicate keys, non-scalar keys and keys not in `known`.
ReadError CheckKeys(const YamlNode& node,
                    const std::string& prefix,
                    const std::vector<std::string>& known);

/// Visitor that lists the keys an options struct accepts.
class KeyCollector {
 public:
  template <class T>
  void operator()(const char* key, T& /*field*/, const FieldSpec& /*spec*/ = FieldSpec()) {
    keys_.emplace_back(key);
  }
  const std::vector<std::string>& keys() const { return keys_; }

 private:
  std::vector<std::string> keys_;
};

template <class T>
ReadError ReadValue(const YamlNode& node, const std::string& key, T* value);

/// Reads the map `node` into `*options`. Fields whose key is absent keep their
/// value. On error `*options` may be partly written: callers read into a copy.
template <class Options>
ReadError ReadOptions(const YamlNode& node, const std::string& prefix, Options* options);

/// Visitor that reads each present key into its field; stops at the first error.
class OptionsReader {
 public:
  OptionsReader(const YamlNode& node, const std::string& prefix) : node_(node), prefix_(prefix) {}

  template <class T>
  void operator()(const char* key, T& field, const FieldSpec& /*spec*/ = FieldSpec()) {
    if (!error_.ok()) return;
    const YamlNode child = node_.Child(key);
    if (!child.IsDefined()) return;  // a missing key keeps the default
    error_ = ReadValue(child, JoinKey(prefix_, key), &field);
  }

  const ReadError& error() const { return error_; }

 private:
  const YamlNode& node_;
  const std::string& prefix_;
  ReadError error_;
};

template <class T>
ReadError ReadValue(const YamlNode& node, const std::string& key, T* value) {
  if constexpr (IsOptionsStruct<T>::value) {
    return ReadOptions(node, key, value);
  } else if constexpr (IsOptionsList<T>::value) {
    ReadError error = ExpectList(node, key);
    if (!error.ok() || node.IsNull()) return error;
    T parsed(node.size());  // every element starts from a default-constructed struct
    for (std::size_t i = 0; i < node.size() && error.ok(); ++i) {
      error = ReadOptions(node.Element(i), IndexKey(key, i), &parsed[i]);
    }
    if (error.ok()) *value = std::move(parsed);
    return error;
  } else if constexpr (std::is_enum_v<T>) {
    static_assert(HasEnumTraits<T>::value, "enum option fields need an EnumTraits specialisation");
    std::string name;
    ReadError error = DecodeValue(node, key, &name);
    if (error.ok() && !EnumFromString(name, value)) {
      error = UnknownEnumValue(node, key, EnumChoices<T>());
    }
    return error;
  } else if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    static_assert(sizeof(T) < sizeof(int64_t) || std::is_signed_v<T>,
                  "uint64_t option fields are not supported");
    int64_t parsed = 0;
    ReadError error = DecodeInteger(node, key, std::numeric_limits<T>::min(),
                                    std::numeric_limits<T>::max(), &parsed);
    if (error.ok()) *value = static_cast<T>(parsed);
    return error;
  } else {
    return DecodeValue(node, key, value);  // no overload: unsupported option field type
  }
}

template <class Options>
ReadError ReadOptions(const YamlNode& node, const std::string& prefix, Options* options) {
  ReadError error = ExpectSection(node, prefix);
  if (!error.ok() || node.IsNull()) return error;
  KeyCollector collector;
  options->VisitFields(collector);
  error = CheckKeys(node, prefix, collector.keys());
  if (!error.ok()) return error;
  OptionsReader reader(node, prefix);
  options->VisitFields(reader);
  return reader.error();
}

}  // namespace swarmlio::config::internal
