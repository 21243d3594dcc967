// ConfigFile: the one YAML loader that maps configs/*.yaml onto options structs.
//
//   config::ConfigFile file;
//   SWARMLIO_RETURN_IF_ERROR(config::ConfigFile::Load("configs/livox_avia.yaml", &file));
//   LidarOptions lidar;
//   SWARMLIO_RETURN_IF_ERROR(file.Read("lidar", &lidar));
//   SWARMLIO_RETURN_IF_ERROR(file.CheckNoUnusedSections());
//
// Every error names the file, the line when known, the full key and the
// reason: "configs/x.yaml:12: lidar.blind_range_m: value -1 is out of range
// (must be >= 0 m)". A key missing from the file keeps the struct's value; an
// unknown key, a wrong type or a value that fails the struct's Validate() is an
// error, and then the struct is left unchanged (all-or-nothing).
#pragma once

#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "swarmlio/common/option_fields.h"
#include "swarmlio/common/status.h"
#include "swarmlio/config/options_reader.h"
#include "swarmlio/config/yaml_node.h"

namespace swarmlio::config {

class ConfigFile {
 public:
  /// An empty configuration: every Read() keeps the defaults.
  ConfigFile() = default;

  /// Reads and parses `path`. NotFound if it cannot be opened; InvalidArgument
  /// naming file and line for a YAML syntax error or a non-map top level.
  static Status Load(const std::string& path, ConfigFile* out);
  /// Same as Load() for text already in memory; `name` stands for the file name
  /// in error messages.
  static Status Parse(const std::string& yaml_text, const std::string& name, ConfigFile* out);

  /// The file name used in messages.
  const std::string& name() const { return name_; }

  /// Reads `section` (a top-level key, a key path like "estimator.lidar" or
  /// "drones[2].lidar", or "" for the whole file) into `*options` and
  /// validates the result. A missing section keeps `*options` (still
  /// validated); reading a section again applies its keys over `*options`
  /// (e.g. over values taken from a preset file). On error `*options` is
  /// unchanged.
  template <class Options>
  Status Read(const std::string& section, Options* options) const;

  /// True if `section` exists (as a map or an empty value).
  bool HasSection(const std::string& section) const;
  /// True if the key path (e.g. "bag.lidar_format", "drones[1].name") is in
  /// the file, whatever its value.
  bool HasKey(const std::string& key) const;
  /// InvalidArgument "<file>:<line>: <key>: <reason>" for checks made by the
  /// caller after Read(); the line is that of `key`, or of its closest
  /// enclosing key in the file (none when not even its section is there).
  Status KeyError(const std::string& key, const std::string& reason) const;
  /// Top-level keys in file order.
  std::vector<std::string> TopLevelKeys() const;
  /// Error naming the first top-level key that no Read() consumed so far.
  Status CheckNoUnusedSections() const;

 private:
  Status FindSection(const std::string& section, YamlNode* node) const;
  Status MakeReadError(const internal::ReadError& error) const;
  Status MakeValidationError(const std::string& section, const std::string& message) const;
  int LineOf(const std::string& key) const;

  std::string name_;
  YamlNode root_;
  // Top-level keys consumed by Read(); bookkeeping only, hence mutable.
  // A ConfigFile is not meant to be read from several threads at once.
  mutable std::set<std::string> used_;
};

template <class Options>
Status ConfigFile::Read(const std::string& section, Options* options) const {
  static_assert(IsOptionsStruct<Options>::value, "Read() needs a struct with VisitFields()");
  if (options == nullptr) return Status::InvalidArgument("ConfigFile::Read: options is null");
  YamlNode node;
  SWARMLIO_RETURN_IF_ERROR(FindSection(section, &node));
  Options candidate = *options;
  if (node.IsDefined()) {
    const internal::ReadError error = internal::ReadOptions(node, section, &candidate);
    if (!error.ok()) return MakeReadError(error);
  }
  const std::string invalid = candidate.Validate();
  if (!invalid.empty()) {
    return MakeValidationError(section, internal::ResolveMessageKey(candidate, invalid));
  }
  *options = std::move(candidate);
  return Status::Ok();
}

}  // namespace swarmlio::config
