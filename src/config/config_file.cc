#include "swarmlio/config/config_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

namespace swarmlio::config {
namespace {

// "file:line: key: reason", leaving out the parts that are unknown.
std::string Located(const std::string& name,
                    int line,
                    const std::string& key,
                    const std::string& reason) {
  std::string out = name;
  if (line > 0) out += ":" + std::to_string(line);
  out += ": ";
  if (!key.empty()) out += key + ": ";
  return out + reason;
}

std::string FirstComponent(const std::string& section) {
  return section.substr(0, section.find_first_of(".["));
}

}  // namespace

Status ConfigFile::Load(const std::string& path, ConfigFile* out) {
  if (out == nullptr) return Status::InvalidArgument("ConfigFile::Load: out is null");
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) {
    return Status::NotFound(path + ": config file not found");
  }
  if (std::filesystem::is_directory(status)) {
    return Status::InvalidArgument(path + ": is a directory, expected a YAML file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::IoError(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return Status::IoError(path + ": read error");
  return Parse(text.str(), path, out);
}

Status ConfigFile::Parse(const std::string& yaml_text, const std::string& name, ConfigFile* out) {
  if (out == nullptr) return Status::InvalidArgument("ConfigFile::Parse: out is null");
  YamlNode root;
  int line = 0;
  std::string message;
  if (!YamlDocument::Parse(yaml_text, &root, &line, &message)) {
    return Status::InvalidArgument(Located(name, line, "", "YAML syntax error: " + message));
  }
  if (!root.IsMap() && !root.IsNull()) {
    return Status::InvalidArgument(
        Located(name, root.line(), "",
                "expected a map of sections at the top level, got " + root.Describe()));
  }
  ConfigFile file;
  file.name_ = name;
  file.root_ = std::move(root);
  *out = std::move(file);
  return Status::Ok();
}

bool ConfigFile::HasSection(const std::string& section) const {
  const YamlNode node = section.empty() ? root_ : root_.FindPath(section);
  return node.IsMap() || (node.IsNull() && !section.empty());
}

std::vector<std::string> ConfigFile::TopLevelKeys() const {
  std::vector<std::string> keys;
  for (const YamlNode::Entry& entry : root_.Entries()) keys.push_back(entry.key);
  return keys;
}

Status ConfigFile::CheckNoUnusedSections() const {
  const std::vector<std::string> used(used_.begin(), used_.end());
  for (const YamlNode::Entry& entry : root_.Entries()) {
    if (used_.count(entry.key) != 0) continue;
    return Status::InvalidArgument(Located(
        name_, entry.line, entry.key, internal::UnknownNameReason("section", entry.key, used)));
  }
  return Status::Ok();
}

Status ConfigFile::FindSection(const std::string& section, YamlNode* node) const {
  *node = YamlNode();
  if (section.empty()) {
    for (const YamlNode::Entry& entry : root_.Entries()) used_.insert(entry.key);
    *node = root_;
    return Status::Ok();
  }
  used_.insert(FirstComponent(section));
  // Walk the path one key or [index] at a time so that a value of the wrong
  // kind in the middle is reported by name.
  YamlNode current = root_;
  std::size_t pos = 0;
  while (pos < section.size()) {
    if (section[pos] == '.') {
      ++pos;
      continue;
    }
    const bool index = section[pos] == '[';
    std::size_t stop = index ? section.find(']', pos) : section.find_first_of(".[", pos);
    stop = stop == std::string::npos ? section.size() : stop + (index ? 1 : 0);
    if (index ? !current.IsSequence() : !current.IsMap()) {
      if (current.IsNull()) return Status::Ok();  // an empty parent: nothing below it
      std::string parent = section.substr(0, pos);
      if (!parent.empty() && parent.back() == '.') parent.pop_back();
      return Status::InvalidArgument(Located(
          name_, current.line(), parent,
          std::string("expected ") + (index ? "a list" : "a section (a map of key: value)") +
              ", got " + current.Describe()));
    }
    current = current.FindPath(section.substr(pos, stop - pos));
    if (!current.IsDefined()) return Status::Ok();  // missing: the caller keeps its values
    pos = stop;
  }
  *node = current;
  return Status::Ok();
}

bool ConfigFile::HasKey(const std::string& key) const {
  return !key.empty() && root_.FindPath(key).IsDefined();
}

Status ConfigFile::KeyError(const std::string& key, const std::string& reason) const {
  return Status::InvalidArgument(Located(name_, LineOf(key), key, reason));
}

int ConfigFile::LineOf(const std::string& key) const {
  std::string path = key;
  while (!path.empty()) {
    const YamlNode node = root_.FindPath(path);
    if (node.IsDefined()) return node.line();
    const std::size_t cut = path.find_last_of(".[");
    path = cut == std::string::npos ? std::string() : path.substr(0, cut);
  }
  return 0;
}

Status ConfigFile::MakeReadError(const internal::ReadError& error) const {
  return Status::InvalidArgument(Located(name_, error.line, error.key, error.reason));
}

Status ConfigFile::MakeValidationError(const std::string& section,
                                       const std::string& message) const {
  // Validate() returns "key: reason" with the key relative to the section.
  const std::size_t colon = message.find(": ");
  const std::string key = colon == std::string::npos ? "" : message.substr(0, colon);
  if (colon == std::string::npos || key.find(' ') != std::string::npos) {
    return Status::InvalidArgument(Located(name_, 0, section, message));
  }
  return KeyError(internal::JoinKey(section, key), message.substr(colon + 2));
}

}  // namespace swarmlio::config
