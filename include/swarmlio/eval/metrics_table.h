// A small table of metrics (columns, rows of named values) that writes
// Markdown, CSV and JSON.
//
//   MetricsTable table;
//   table.AddColumn({"drone", "drone"});
//   table.AddColumn({"ape_rmse_m", "APE rmse [m]", 4});
//   table.AddRow({{"drone", std::string("uav0")}, {"ape_rmse_m", 0.0123}});
//   table.WriteAll("results/run1/metrics");  // metrics.md, .csv, .json
//
// Numbers go to CSV and JSON in the shortest form that reads back to the same
// double, and to Markdown with the column's number of decimals. A missing cell
// or a non-finite number is empty in CSV, null in JSON and "n/a" in Markdown.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "swarmlio/common/status.h"

namespace swarmlio::eval {

/// A cell value: a number or text.
using MetricsValue = std::variant<double, std::string>;

struct MetricsColumn {
  std::string key;     // CSV header and JSON key: letters, digits, '_', '.', '-'
  std::string header;  // Markdown header, e.g. "APE rmse [m]"; empty = key
  int decimals = 4;    // Markdown digits after the point (numbers only), 0..17
};

enum class TableFormat { kMarkdown, kCsv, kJson };

class MetricsTable {
 public:
  /// Errors: an empty or invalid key, a key already used, bad decimals.
  Status AddColumn(const MetricsColumn& column);

  /// Adds a row of (column key, value); columns not named stay empty.
  /// Errors: an unknown or repeated key.
  Status AddRow(const std::vector<std::pair<std::string, MetricsValue>>& cells);

  const std::vector<MetricsColumn>& columns() const { return columns_; }
  size_t num_rows() const { return rows_.size(); }

  std::string ToMarkdown() const;
  std::string ToCsv() const;
  /// {"columns": [{"key": ..., "header": ...}, ...], "rows": [{key: value, ...}, ...]}
  std::string ToJson() const;
  std::string Format(TableFormat format) const;

  Status WriteFile(const std::string& path, TableFormat format) const;
  /// Writes path_stem + ".md", ".csv" and ".json".
  Status WriteAll(const std::string& path_stem) const;

 private:
  using Cell = std::variant<std::monostate, double, std::string>;
  std::vector<MetricsColumn> columns_;
  std::vector<std::vector<Cell>> rows_;
};

}  // namespace swarmlio::eval
