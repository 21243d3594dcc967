#include "swarmlio/config/dump_options.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace swarmlio::config::internal {
namespace {

template <class Range, class Format>
std::string FormatList(const Range& values, Format format) {
  std::string out = "[";
  bool first = true;
  for (const auto& v : values) {
    if (!first) out += ", ";
    out += format(v);
    first = false;
  }
  return out + "]";
}

void AppendIndent(int indent, std::string* out) { out->append(static_cast<size_t>(indent), ' '); }

}  // namespace

std::string FormatValue(bool value) { return value ? "true" : "false"; }

std::string FormatValue(int64_t value) { return std::to_string(value); }

std::string FormatValue(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  char buffer[64];
  // Shortest representation that parses back to the same double.
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string FormatValue(const std::string& value) {
  std::string out = "\"";
  for (const char c : value) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof(escaped), "\\x%02x", static_cast<unsigned>(c));
          out += escaped;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string FormatValue(const Eigen::Vector3d& value) {
  return FormatList(std::vector<double>{value.x(), value.y(), value.z()},
                    [](double v) { return FormatValue(v); });
}

std::string FormatValue(const Eigen::Matrix3d& value) {
  std::string out = "[";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      out += FormatValue(value(r, c));
      if (r < 2 || c < 2) out += (c == 2 ? ",  " : ", ");  // two spaces between rows
    }
  }
  return out + "]";
}

std::string FormatValue(const std::vector<double>& value) {
  return FormatList(value, [](double v) { return FormatValue(v); });
}

std::string FormatValue(const std::vector<std::string>& value) {
  return FormatList(value, [](const std::string& v) { return FormatValue(v); });
}

void AppendComment(const FieldSpec& spec, const std::string& extra, int indent, std::string* out) {
  std::string text = spec.doc;
  if (spec.unit[0] != '\0') text += std::string(text.empty() ? "" : " ") + "[" + spec.unit + "]";
  FieldSpec range_only = spec;
  range_only.unit = "";
  const std::string range = FormatRange(range_only);
  if (!range.empty()) text += (text.empty() ? "" : "; ") + range;
  if (!extra.empty()) text += (text.empty() ? "" : "; ") + extra;
  if (text.empty()) return;
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  AppendIndent(indent, out);
  *out += "# " + text + "\n";
}

void AppendEntry(const std::string& key, const std::string& value, int indent, std::string* out) {
  AppendIndent(indent, out);
  *out += key + ":";
  if (!value.empty()) *out += " " + value;
  *out += "\n";
}

void AppendListItem(const std::string& body, int indent, std::string* out) {
  AppendIndent(indent, out);
  if (body.empty()) {
    *out += "- {}\n";
    return;
  }
  // The body's first line starts with indent + 2 spaces; the marker takes the last two.
  *out += "- " + body.substr(static_cast<size_t>(indent) + 2);
}

}  // namespace swarmlio::config::internal
