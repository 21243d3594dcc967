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

#include "swarmlio/common/option_fields.h"
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
/// A key that lives in a field group of the struct: {key, group}.
using GroupedKey = std::pair<std::string, std::string>;
/// Rejects duplicate keys, non-scalar keys and keys not in `known`; a key that
/// is one of `grouped` gets "moved to <prefix>.<group>.<key>".
ReadError CheckKeys(const YamlNode& node,
                    const std::string& prefix,
                    const std::vector<std::string>& known,
                    const std::vector<GroupedKey>& grouped = {});

/// Visitor that lists the keys an options struct accepts, and the keys of its
/// field groups (config::FieldGroup) with the group that holds them.
class KeyCollector {
 public:
  template <class T>
  void operator()(const char* key, T& field, const FieldSpec& /*spec*/ = FieldSpec()) {
    keys_.emplace_back(key);
    if constexpr (IsFieldGroup<T>::value) {
      KeyCollector inner;
      field.VisitFields(inner);
      for (const std::string& k : inner.keys()) grouped_.emplace_back(k, key);
    } else {
      (void)field;
    }
  }
  const std::vector<std::string>& keys() const { return keys_; }
  const std::vector<GroupedKey>& grouped() const { return grouped_; }

 private:
  std::vector<std::string> keys_;
  std::vector<GroupedKey> grouped_;
};

/// `path`, a key path relative to `options` ("clock_sync.window_s",
/// "links[1].link.seed"), with the field groups that hold its components
/// spelled out ("clock_sync.experimental.window_s"). Validate() messages
/// name fields by their place in the C++ structs; this gives their place in
/// YAML. Components it does not know are kept as given.
template <class Options>
std::string ResolveKeyPath(Options& options, const std::string& path);

/// Resolves the part of `rest` (the path after a field, "" or ".x..." or
/// "[i]...") below `field`.
template <class T>
std::string ResolveTail(T& field, const std::string& rest) {
  if (rest.empty()) return rest;
  if constexpr (IsOptionsStruct<T>::value) {
    if (rest[0] == '.') return "." + ResolveKeyPath(field, rest.substr(1));
  } else if constexpr (IsOptionsList<T>::value) {
    const std::size_t close = rest.find(']');
    if (rest[0] == '[' && close != std::string::npos) {
      const std::string digits = rest.substr(1, close - 1);
      if (!digits.empty() && digits.size() < 10 &&
          digits.find_first_not_of("0123456789") == std::string::npos) {
        const std::size_t i = std::stoul(digits);
        if (i < field.size()) return rest.substr(0, close + 1) + ResolveTail(field[i], rest.substr(close + 1));
      }
    }
  }
  return rest;
}

/// Visitor behind ResolveKeyPath: finds the field named `name`, directly or
/// inside a field group.
class KeyPathResolver {
 public:
  KeyPathResolver(std::string name, std::string rest)
      : name_(std::move(name)), rest_(std::move(rest)) {}

  template <class T>
  void operator()(const char* key, T& field, const FieldSpec& /*spec*/ = FieldSpec()) {
    if (found_) return;
    if (name_ == key) {
      found_ = true;
      resolved_ = key + ResolveTail(field, rest_);
    } else if constexpr (IsFieldGroup<T>::value) {
      KeyPathResolver inner(name_, rest_);
      field.VisitFields(inner);
      if (inner.found()) {
        found_ = true;
        resolved_ = std::string(key) + "." + inner.resolved();
      }
    }
  }
  bool found() const { return found_; }
  const std::string& resolved() const { return resolved_; }

 private:
  std::string name_;
  std::string rest_;
  bool found_ = false;
  std::string resolved_;
};

template <class Options>
std::string ResolveKeyPath(Options& options, const std::string& path) {
  const std::size_t cut = path.find_first_of(".[");
  const std::string name = path.substr(0, cut);
  if (name.empty()) return path;
  KeyPathResolver resolver(name, cut == std::string::npos ? "" : path.substr(cut));
  options.VisitFields(resolver);
  return resolver.found() ? resolver.resolved() : path;
}

/// A Validate() message "key: reason" with its key resolved (ResolveKeyPath);
/// other messages unchanged.
template <class Options>
std::string ResolveMessageKey(const Options& options, const std::string& message) {
  const std::size_t colon = message.find(": ");
  if (colon == std::string::npos || colon == 0) return message;
  const std::string key = message.substr(0, colon);
  if (key.find(' ') != std::string::npos) return message;
  Options copy = options;  // VisitFields() is non-const by design
  return ResolveKeyPath(copy, key) + message.substr(colon);
}

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
  error = CheckKeys(node, prefix, collector.keys(), collector.grouped());
  if (!error.ok()) return error;
  OptionsReader reader(node, prefix);
  options->VisitFields(reader);
  return reader.error();
}

}  // namespace swarmlio::config::internal
