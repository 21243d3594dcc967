// genmsg's rules for message definitions, to check the MD5 of the message
// types we define ourselves (livox CustomMsg, nav_msgs/Odometry) from their
// full definition text.
#pragma once

#include <gtest/gtest.h>

#include <boost/uuid/detail/md5.hpp>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>
#include <string>

namespace swarmlio::io::testing {

inline std::string Md5Hex(const std::string& text) {
  boost::uuids::detail::md5 hash;
  hash.process_bytes(text.data(), text.size());
  boost::uuids::detail::md5::digest_type digest;
  hash.get_digest(digest);
  char hex[33];
  for (int i = 0; i < 4; ++i) std::snprintf(hex + 8 * i, 9, "%08x", digest[i]);
  return std::string(hex, 32);
}

// Splits a genmsg full definition into {full type name -> message text}.
inline std::map<std::string, std::string> SplitDefinition(const std::string& top_type,
                                                          const std::string& full_text) {
  const std::string separator = "\n" + std::string(80, '=') + "\n";
  std::map<std::string, std::string> sections;
  size_t start = 0;
  std::string type = top_type;
  while (true) {
    const size_t end = full_text.find(separator, start);
    sections[type] = full_text.substr(start, end == std::string::npos ? end : end - start);
    if (end == std::string::npos) break;
    start = end + separator.size();
    const size_t line_end = full_text.find('\n', start);
    const std::string msg_line = full_text.substr(start, line_end - start);
    EXPECT_EQ(msg_line.rfind("MSG: ", 0), 0u) << msg_line;
    type = msg_line.substr(5);
    start = line_end + 1;
  }
  return sections;
}

// genmsg's MD5: over "type name" lines of the comment-stripped fields, with
// nested message types replaced by their own MD5 (array suffix dropped).
inline std::string GenmsgMd5(const std::string& type,
                             const std::map<std::string, std::string>& sections) {
  static const std::set<std::string> kBuiltins = {
      "bool",   "int8",    "uint8",   "int16",  "uint16", "int32",    "uint32", "int64",
      "uint64", "float32", "float64", "string", "time",   "duration", "byte",   "char"};
  const std::string package = type.substr(0, type.find('/'));
  std::istringstream lines(sections.at(type));
  std::string line, md5_text;
  while (std::getline(lines, line)) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string field_type, name;
    if (!(words >> field_type >> name)) continue;
    const std::string bare = field_type.substr(0, field_type.find('['));
    if (!md5_text.empty()) md5_text += "\n";
    if (kBuiltins.count(bare) > 0) {
      md5_text += field_type + " " + name;
    } else {
      std::string full = bare;
      if (bare == "Header")
        full = "std_msgs/Header";
      else if (bare.find('/') == std::string::npos)
        full = package + "/" + bare;
      md5_text += GenmsgMd5(full, sections) + " " + name;
    }
  }
  return Md5Hex(md5_text);
}

}  // namespace swarmlio::io::testing
