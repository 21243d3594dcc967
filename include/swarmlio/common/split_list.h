// SplitList: the non-empty items of a separated list ("a,b,,c" -> a, b, c),
// for command-line flags that take lists.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace swarmlio {

inline std::vector<std::string> SplitList(const std::string& list, char separator = ',') {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, separator);) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace swarmlio
