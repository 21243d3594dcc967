// DumpOptions: renders an options struct as YAML that ConfigFile reads back
// to identical values, with each field's doc, unit and range as a comment:
//
//   lidar:
//     # points closer than this are dropped [m]; >= 0
//     blind_range_m: 0.5
//
// Used by tools/config (swarmlio_config_check) and to regenerate the tables in
// docs/configuration.md. Doubles are printed with the shortest text that
// parses back to the same bits.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <type_traits>
#include <vector>

#include "swarmlio/common/option_fields.h"

namespace swarmlio::config {
namespace internal {

// Value formatting (src/config/dump_options.cc).
std::string FormatValue(bool value);
std::string FormatValue(int64_t value);
std::string FormatValue(double value);
std::string FormatValue(const std::string& value);
std::string FormatValue(const Eigen::Vector3d& value);
std::string FormatValue(const Eigen::Matrix3d& value);
std::string FormatValue(const std::vector<double>& value);
std::string FormatValue(const std::vector<std::string>& value);

/// Appends "<indent># doc [unit]; range; extra\n" (nothing if all are empty).
void AppendComment(const FieldSpec& spec, const std::string& extra, int indent, std::string* out);
/// Appends "<indent>key: value\n".
void AppendEntry(const std::string& key, const std::string& value, int indent, std::string* out);
/// Appends one element of a YAML list: `body` holds its fields at indent
/// `indent + 2`; the first line gets the "- " marker at `indent`.
void AppendListItem(const std::string& body, int indent, std::string* out);

/// Visitor that writes one YAML line (plus comment) per field.
class YamlDumper {
 public:
  YamlDumper(int indent, std::string* out) : indent_(indent), out_(out) {}

  template <class T>
  void operator()(const char* key, T& field, const FieldSpec& spec = FieldSpec()) {
    if constexpr (IsOptionsStruct<T>::value) {
      AppendComment(spec, "", indent_, out_);
      std::string body;
      YamlDumper nested(indent_ + 2, &body);
      field.VisitFields(nested);
      AppendEntry(key, body.empty() ? "{}" : "", indent_, out_);
      *out_ += body;
    } else if constexpr (IsOptionsList<T>::value) {
      AppendComment(spec, "", indent_, out_);
      AppendEntry(key, field.empty() ? "[]" : "", indent_, out_);
      for (auto& element : field) {
        std::string body;
        YamlDumper nested(indent_ + 4, &body);
        element.VisitFields(nested);
        AppendListItem(body, indent_ + 2, out_);
      }
    } else if constexpr (std::is_enum_v<T>) {
      AppendComment(spec, "one of: " + EnumChoices<T>(), indent_, out_);
      AppendEntry(key, EnumToString(field), indent_, out_);
    } else if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
      AppendComment(spec, "", indent_, out_);
      AppendEntry(key, FormatValue(static_cast<int64_t>(field)), indent_, out_);
    } else if constexpr (std::is_same_v<T, float>) {
      AppendComment(spec, "", indent_, out_);
      AppendEntry(key, FormatValue(static_cast<double>(field)), indent_, out_);
    } else {
      AppendComment(spec, std::is_same_v<T, Eigen::Matrix3d> ? "row-major" : "", indent_, out_);
      AppendEntry(key, FormatValue(field), indent_, out_);
    }
  }

 private:
  int indent_;
  std::string* out_;
};

}  // namespace internal

/// YAML text for `options`; under a `section:` key when `section` is not
/// empty (a dotted section such as "a.b" becomes nested maps).
template <class Options>
std::string DumpOptions(const Options& options, const std::string& section = "") {
  static_assert(IsOptionsStruct<Options>::value, "DumpOptions() needs a struct with VisitFields()");
  Options copy = options;  // VisitFields() is non-const by design
  std::string out;
  int indent = 0;
  std::string::size_type begin = 0;
  while (!section.empty() && begin <= section.size()) {
    std::string::size_type end = section.find('.', begin);
    if (end == std::string::npos) end = section.size();
    internal::AppendEntry(section.substr(begin, end - begin), "", indent, &out);
    indent += 2;
    begin = end + 1;
  }
  internal::YamlDumper dumper(indent, &out);
  copy.VisitFields(dumper);
  return out;
}

}  // namespace swarmlio::config
