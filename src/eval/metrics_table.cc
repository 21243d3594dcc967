#include "swarmlio/eval/metrics_table.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace swarmlio::eval {

namespace {

constexpr int kMaxDecimals = 17;
constexpr const char* kMissingMarkdown = "n/a";

bool IsValidKey(const std::string& key) {
  if (key.empty()) return false;
  return std::all_of(key.begin(), key.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '.' || c == '-';
  });
}

/// Shortest text that reads back to the same double.
std::string ShortestNumber(double value) {
  char buffer[64];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, r.ptr);
}

std::string FixedNumber(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
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
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char escaped[8];
          std::snprintf(escaped, sizeof(escaped), "\\u%04x", static_cast<unsigned>(c));
          out += escaped;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string MarkdownText(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '|') out += '\\';
    out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return out;
}

}  // namespace

Status MetricsTable::AddColumn(const MetricsColumn& column) {
  if (!IsValidKey(column.key)) {
    return Status::InvalidArgument("metrics table: invalid column key '" + column.key + "'");
  }
  for (const MetricsColumn& existing : columns_) {
    if (existing.key == column.key) {
      return Status::InvalidArgument("metrics table: duplicate column '" + column.key + "'");
    }
  }
  if (column.decimals < 0 || column.decimals > kMaxDecimals) {
    return Status::InvalidArgument("metrics table: column '" + column.key +
                                   "' decimals must be in [0, 17]");
  }
  columns_.push_back(column);
  for (std::vector<Cell>& row : rows_) row.emplace_back();
  return Status::Ok();
}

Status MetricsTable::AddRow(const std::vector<std::pair<std::string, MetricsValue>>& cells) {
  std::vector<Cell> row(columns_.size());
  std::vector<bool> set(columns_.size(), false);
  for (const auto& [key, value] : cells) {
    const auto it = std::find_if(columns_.begin(), columns_.end(),
                                 [&](const MetricsColumn& c) { return c.key == key; });
    if (it == columns_.end()) {
      return Status::InvalidArgument("metrics table: unknown column '" + key + "'");
    }
    const size_t index = static_cast<size_t>(it - columns_.begin());
    if (set[index]) return Status::InvalidArgument("metrics table: column '" + key + "' set twice");
    set[index] = true;
    if (const double* number = std::get_if<double>(&value)) {
      row[index] = *number;
    } else {
      row[index] = std::get<std::string>(value);
    }
  }
  rows_.push_back(std::move(row));
  return Status::Ok();
}

std::string MetricsTable::ToMarkdown() const {
  const size_t n = columns_.size();
  std::vector<std::vector<std::string>> text(rows_.size(), std::vector<std::string>(n));
  std::vector<bool> numeric(n, true);
  std::vector<size_t> width(n, 3);
  for (size_t c = 0; c < n; ++c) {
    const std::string header =
        MarkdownText(columns_[c].header.empty() ? columns_[c].key : columns_[c].header);
    width[c] = std::max(width[c], header.size());
    for (size_t r = 0; r < rows_.size(); ++r) {
      const Cell& cell = rows_[r][c];
      std::string& out = text[r][c];
      if (const double* number = std::get_if<double>(&cell)) {
        out =
            std::isfinite(*number) ? FixedNumber(*number, columns_[c].decimals) : kMissingMarkdown;
      } else if (const std::string* s = std::get_if<std::string>(&cell)) {
        out = MarkdownText(*s);
        numeric[c] = false;
      } else {
        out = kMissingMarkdown;
      }
      width[c] = std::max(width[c], out.size());
    }
  }
  std::ostringstream md;
  auto pad = [&](const std::string& s, size_t c) {
    const std::string fill(width[c] - s.size(), ' ');
    return numeric[c] ? fill + s : s + fill;
  };
  md << "|";
  for (size_t c = 0; c < n; ++c) {
    md << " "
       << pad(MarkdownText(columns_[c].header.empty() ? columns_[c].key : columns_[c].header), c)
       << " |";
  }
  md << "\n|";
  for (size_t c = 0; c < n; ++c) {
    md << (numeric[c] ? " " + std::string(width[c] - 1, '-') + ":"
                      : " " + std::string(width[c], '-'))
       << " |";
  }
  md << "\n";
  for (const std::vector<std::string>& row : text) {
    md << "|";
    for (size_t c = 0; c < n; ++c) md << " " << pad(row[c], c) << " |";
    md << "\n";
  }
  return md.str();
}

std::string MetricsTable::ToCsv() const {
  std::ostringstream csv;
  for (size_t c = 0; c < columns_.size(); ++c) csv << (c ? "," : "") << columns_[c].key;
  csv << "\n";
  for (const std::vector<Cell>& row : rows_) {
    for (size_t c = 0; c < row.size(); ++c) {
      if (c) csv << ",";
      if (const double* number = std::get_if<double>(&row[c])) {
        if (std::isfinite(*number)) csv << ShortestNumber(*number);
      } else if (const std::string* s = std::get_if<std::string>(&row[c])) {
        csv << CsvField(*s);
      }
    }
    csv << "\n";
  }
  return csv.str();
}

std::string MetricsTable::ToJson() const {
  std::ostringstream json;
  json << "{\n  \"columns\": [";
  for (size_t c = 0; c < columns_.size(); ++c) {
    json << (c ? ",\n    " : "\n    ") << "{\"key\": " << JsonString(columns_[c].key)
         << ", \"header\": "
         << JsonString(columns_[c].header.empty() ? columns_[c].key : columns_[c].header) << "}";
  }
  json << (columns_.empty() ? "],\n" : "\n  ],\n") << "  \"rows\": [";
  for (size_t r = 0; r < rows_.size(); ++r) {
    json << (r ? ",\n    {" : "\n    {");
    for (size_t c = 0; c < columns_.size(); ++c) {
      json << (c ? ", " : "") << JsonString(columns_[c].key) << ": ";
      const Cell& cell = rows_[r][c];
      if (const double* number = std::get_if<double>(&cell)) {
        json << (std::isfinite(*number) ? ShortestNumber(*number) : "null");
      } else if (const std::string* s = std::get_if<std::string>(&cell)) {
        json << JsonString(*s);
      } else {
        json << "null";
      }
    }
    json << "}";
  }
  json << (rows_.empty() ? "]\n}\n" : "\n  ]\n}\n");
  return json.str();
}

std::string MetricsTable::Format(TableFormat format) const {
  switch (format) {
    case TableFormat::kMarkdown:
      return ToMarkdown();
    case TableFormat::kCsv:
      return ToCsv();
    case TableFormat::kJson:
      return ToJson();
  }
  return "";
}

Status MetricsTable::WriteFile(const std::string& path, TableFormat format) const {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file.is_open()) return Status::IoError(path + ": cannot open for writing");
  file << Format(format);
  file.close();
  if (!file) return Status::IoError(path + ": write failed");
  return Status::Ok();
}

Status MetricsTable::WriteAll(const std::string& path_stem) const {
  SWARMLIO_RETURN_IF_ERROR(WriteFile(path_stem + ".md", TableFormat::kMarkdown));
  SWARMLIO_RETURN_IF_ERROR(WriteFile(path_stem + ".csv", TableFormat::kCsv));
  return WriteFile(path_stem + ".json", TableFormat::kJson);
}

}  // namespace swarmlio::eval
