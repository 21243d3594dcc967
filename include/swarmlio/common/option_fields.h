// Options structs describe their own fields once; loading, validation and
// documentation all walk that one description.
//
// Every module owns a plain `*Options` struct with in-class defaults (units in
// the name or comment) and a member template
//
//   template <class Visitor> void VisitFields(Visitor&& v) {
//     v("blind_range", blind_range_m, FieldSpec::AtLeast(0.0, "m", "points closer are dropped"));
//     v("timestamp_unit", timestamp_unit, FieldSpec::Doc("unit of the per-point time field"));
//     v("imu", imu);   // a nested options struct becomes a YAML section
//     v("drones", drones);  // std::vector<DroneOptions>: a YAML list of sections
//   }
//
// and a `std::string Validate() const` that returns "" when valid and
// otherwise a message naming the key (use ValidateFields() for the ranges and
// add cross-field checks). Supported field types: bool, integral types,
// float, double, std::string, Eigen::Vector3d, Eigen::Matrix3d (YAML: 9
// numbers, row-major), std::vector<double>, std::vector<std::string>, enums
// with an EnumTraits<E> specialisation, nested options structs, and
// std::vector of an options struct (a YAML sequence of maps; each element
// starts from a default-constructed struct and is validated on its own; keys
// in messages carry the index, "drones[2].lidar.blind_range_m").
//
// A struct that extends another one with more keys at the same YAML level
// holds it as a member and visits it inline:
//
//   template <class Visitor> void VisitFields(Visitor&& v) {
//     sensor.VisitFields(v);   // the shared keys, unprefixed
//     v("dropout_probability", dropout_probability, FieldSpec::InRange(0, 1, "", "..."));
//   }
//
// Research toggles and tuning knobs that users rarely set go into a field
// group: a nested YAML map with no C++ sub-struct of its own. The fields stay
// members of the struct; only the YAML path changes:
//
//   template <class Visitor> void VisitFields(Visitor&& v) {
//     v("fuse_active", fuse_active, FieldSpec::Doc("..."));   // swarm.fuse_active
//     config::VisitExperimental(v, [&](auto& x) {              // swarm.experimental.gate_sigma
//       x("gate_sigma", gate_sigma, FieldSpec::Positive("", "..."));
//     });
//   }
//
// A group is visited like a nested options struct (FieldGroup has
// VisitFields() and Validate()), so every visitor that handles nested structs
// handles it. A struct visits at most one group of a given name (inline
// extensions included). The loader reports a grouped key found at the
// struct's own level as moved ("swarm.gate_sigma: moved to
// swarm.experimental.gate_sigma"). Validate() messages name a grouped field
// by its C++ path ("clock_sync.window_s", as code sets it); ConfigFile::Read
// gives it its YAML path ("clock_sync.experimental.window_s").
//
// Loading from YAML: config/config_file.h. Rendering as documented YAML:
// config/dump_options.h.
//
// Default-constructed options are pure values: nothing here touches files.
//
// Header-only, in common/ because every module's options include it (no
// module links swarmlio_config for it). Its names stay in namespace
// swarmlio::config, spelt config::FieldSpec, config::ValidateFields, ... in
// every module, next to config::ConfigFile and config::DumpOptions.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace swarmlio::config {

/// Range, unit and one-line documentation of one option field.
struct FieldSpec {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
  const char* unit = "";
  const char* doc = "";

  static FieldSpec Doc(const char* doc, const char* unit = "") {
    FieldSpec s;
    s.unit = unit;
    s.doc = doc;
    return s;
  }
  static FieldSpec AtLeast(double lo, const char* unit, const char* doc) {
    FieldSpec s = Doc(doc, unit);
    s.min = lo;
    return s;
  }
  static FieldSpec Positive(const char* unit, const char* doc) {
    FieldSpec s = AtLeast(0.0, unit, doc);
    s.min_exclusive = true;
    return s;
  }
  static FieldSpec InRange(double lo, double hi, const char* unit, const char* doc) {
    FieldSpec s = AtLeast(lo, unit, doc);
    s.max = hi;
    return s;
  }
  /// Copy with an upper bound, e.g. FieldSpec::Positive("Hz", "...").WithMax(1000).
  FieldSpec WithMax(double hi) const {
    FieldSpec s = *this;
    s.max = hi;
    return s;
  }
};

/// Specialise for an enum used in options:
///   template <> struct EnumTraits<TimestampUnit> {
///     static constexpr std::array<std::pair<TimestampUnit, const char*>, 4> kNames{{...}};
///   };
template <class E>
struct EnumTraits;

template <class E, class = void>
struct HasEnumTraits : std::false_type {};
template <class E>
struct HasEnumTraits<E, std::void_t<decltype(EnumTraits<E>::kNames)>> : std::true_type {};

template <class E>
const char* EnumToString(E value) {
  for (const auto& [v, name] : EnumTraits<E>::kNames) {
    if (v == value) return name;
  }
  return "?";
}

template <class E>
bool EnumFromString(const std::string& text, E* value) {
  for (const auto& [v, name] : EnumTraits<E>::kNames) {
    if (text == name) {
      *value = v;
      return true;
    }
  }
  return false;
}

template <class E>
std::string EnumChoices() {
  std::string out;
  for (const auto& [v, name] : EnumTraits<E>::kNames) {
    (void)v;
    if (!out.empty()) out += ", ";
    out += name;
  }
  return out;
}

/// True for option structs (they have a VisitFields member template).
template <class T, class = void>
struct IsOptionsStruct : std::false_type {};
struct NullVisitor {
  template <class... A>
  void operator()(A&&...) {}
};
template <class T>
struct IsOptionsStruct<T, std::void_t<decltype(std::declval<T&>().VisitFields(NullVisitor{}))>>
    : std::true_type {};

/// True for std::vector<T> with T an options struct (a YAML list of sections).
template <class T>
struct IsOptionsList : std::false_type {};
template <class T, class A>
struct IsOptionsList<std::vector<T, A>> : IsOptionsStruct<T> {};

/// "key[i]": the key of element `i` of a list, as messages and key paths
/// (ConfigFile::Read, KeyError) spell it.
inline std::string IndexKey(const std::string& key, size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

template <class Options>
std::string ValidateFields(const Options& options);

/// A named group of fields of the enclosing struct, visited as a nested YAML
/// map (see the top of this file). `Body` is a callable taking the visitor:
/// `[&](auto& x) { x("key", member, spec); ... }`. Only a view: it refers to
/// the enclosing struct's members and lives for one VisitFields() call.
template <class Body>
class FieldGroup {
 public:
  explicit FieldGroup(Body body) : body_(std::move(body)) {}

  template <class V>
  void VisitFields(V&& v) {
    body_(v);
  }
  /// Range checks of the grouped fields ("key: reason", key relative to the group).
  /// (ValidateFields of the enclosing struct checks them without the group's name.)
  std::string Validate() const { return ValidateFields(*this); }

 private:
  Body body_;
};

/// True for FieldGroup (a group of fields, not a struct of its own).
template <class T>
struct IsFieldGroup : std::false_type {};
template <class Body>
struct IsFieldGroup<FieldGroup<Body>> : std::true_type {};

/// YAML key of the group that holds a struct's research and tuning fields.
inline constexpr const char* kExperimentalKey = "experimental";

/// Visits the fields that `body` visits as the group `name` of `v`'s struct.
template <class Visitor, class Body>
void VisitGroup(Visitor& v, const char* name, const FieldSpec& spec, Body&& body) {
  FieldGroup<std::decay_t<Body>> group(std::forward<Body>(body));
  v(name, group, spec);
}

/// Visits the fields that `body` visits as the struct's `experimental:` map:
/// research toggles and tuning knobs, loaded, validated and dumped like any
/// other key but kept out of the short user-facing list.
template <class Visitor, class Body>
void VisitExperimental(Visitor& v, Body&& body) {
  VisitGroup(v, kExperimentalKey,
             FieldSpec::Doc("research and tuning keys (docs/configuration.md): the defaults are "
                            "the tested values"),
             std::forward<Body>(body));
}

namespace internal {

/// Prefixes a Validate() message ("key: reason") with `prefix` + ".".
inline std::string PrefixError(const std::string& prefix, const std::string& error) {
  return error.empty() ? error : prefix + "." + error;
}

inline std::string FormatRange(const FieldSpec& spec) {
  std::ostringstream os;
  const bool has_min = std::isfinite(spec.min);
  const bool has_max = std::isfinite(spec.max);
  if (has_min && has_max) {
    os << "in " << (spec.min_exclusive ? "(" : "[") << spec.min << ", " << spec.max << "]";
  } else if (has_min) {
    os << (spec.min_exclusive ? "> " : ">= ") << spec.min;
  } else if (has_max) {
    os << "<= " << spec.max;
  }
  if (spec.unit[0] != '\0') os << " " << spec.unit;
  return os.str();
}

inline bool InRange(double value, const FieldSpec& spec) {
  if (!std::isfinite(value)) return false;
  if (spec.min_exclusive ? !(value > spec.min) : !(value >= spec.min)) return false;
  return value <= spec.max;
}

/// Checks one scalar against its spec; returns "" or "key: reason".
inline std::string CheckScalar(const std::string& key, double value, const FieldSpec& spec) {
  if (InRange(value, spec)) return {};
  std::ostringstream os;
  os << key << ": value " << value << " is out of range (must be ";
  const std::string range = FormatRange(spec);
  os << (range.empty() ? "finite" : range) << ")";
  return os.str();
}

/// Visitor that collects the first range violation.
class RangeChecker {
 public:
  explicit RangeChecker(std::string prefix) : prefix_(std::move(prefix)) {}

  template <class T>
  void operator()(const char* key, T& field, const FieldSpec& spec = FieldSpec()) {
    if (!error_.empty()) return;
    const std::string full = prefix_.empty() ? key : prefix_ + "." + key;
    if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, std::string> ||
                  std::is_same_v<T, std::vector<std::string>> || std::is_enum_v<T>) {
      (void)field;
      (void)spec;
    } else if constexpr (std::is_arithmetic_v<T>) {
      error_ = CheckScalar(full, static_cast<double>(field), spec);
    } else if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
      for (int i = 0; i < 3 && error_.empty(); ++i) {
        error_ = CheckScalar(IndexKey(full, i), field[i], spec);
      }
    } else if constexpr (std::is_same_v<T, Eigen::Matrix3d>) {
      for (int i = 0; i < 9 && error_.empty(); ++i) {  // row-major index, as in YAML
        error_ = CheckScalar(IndexKey(full, i), field(i / 3, i % 3), spec);
      }
    } else if constexpr (std::is_same_v<T, std::vector<double>>) {
      for (size_t i = 0; i < field.size() && error_.empty(); ++i) {
        error_ = CheckScalar(IndexKey(full, i), field[i], spec);
      }
    } else if constexpr (IsFieldGroup<T>::value) {
      (void)spec;
      field.VisitFields(*this);  // no level of its own: keys keep their C++ path
    } else if constexpr (IsOptionsStruct<T>::value) {
      (void)spec;
      error_ = PrefixError(full, field.Validate());
    } else if constexpr (IsOptionsList<T>::value) {
      (void)spec;
      for (size_t i = 0; i < field.size() && error_.empty(); ++i) {
        error_ = PrefixError(IndexKey(full, i), field[i].Validate());
      }
    } else {
      static_assert(sizeof(T) == 0, "unsupported option field type");
    }
  }

  const std::string& error() const { return error_; }

 private:
  std::string prefix_;
  std::string error_;
};

}  // namespace internal

/// Checks every field of `options` against its FieldSpec (and nested
/// structs through their own Validate()). Returns "" or "key: reason".
template <class Options>
std::string ValidateFields(const Options& options) {
  Options copy = options;
  internal::RangeChecker checker("");
  copy.VisitFields(checker);
  return checker.error();
}

}  // namespace swarmlio::config
