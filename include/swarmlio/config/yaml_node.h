// YamlNode: a read-only view of one node of a parsed YAML document.
//
// It hides yaml-cpp from every public header (the library links yaml-cpp
// privately). Copies are cheap and share the document. All accessors are
// non-throwing; conversions report failure through their return value.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace swarmlio::config {

class YamlNode {
 public:
  enum class Kind { kUndefined, kNull, kScalar, kSequence, kMap };

  /// One `key: value` entry of a map, in file order.
  struct Entry {
    std::string key;  // the key's text ("" when the key is not a scalar)
    bool key_is_scalar = true;
    int line = 0;  // 1-based line of the key, 0 when unknown
  };

  YamlNode();  // undefined node
  ~YamlNode();
  YamlNode(const YamlNode&);
  YamlNode& operator=(const YamlNode&);
  YamlNode(YamlNode&&) noexcept;
  YamlNode& operator=(YamlNode&&) noexcept;

  Kind kind() const;
  bool IsDefined() const { return kind() != Kind::kUndefined; }
  bool IsNull() const { return kind() == Kind::kNull; }
  bool IsScalar() const { return kind() == Kind::kScalar; }
  bool IsSequence() const { return kind() == Kind::kSequence; }
  bool IsMap() const { return kind() == Kind::kMap; }

  /// 1-based line of this node: the key's line for a map value (so that an
  /// empty value still has a line), the element's own line otherwise; 0 when
  /// unknown.
  int line() const;

  /// Raw text of a scalar ("" for other kinds).
  std::string Scalar() const;
  /// True for a quoted scalar ('...' or "..."): text, never a number or bool.
  bool IsQuoted() const;

  /// Number of elements of a sequence (0 for other kinds).
  std::size_t size() const;
  /// Element `i` of a sequence; undefined when out of range or not a sequence.
  YamlNode Element(std::size_t i) const;

  /// Entries of a map in file order (empty for other kinds).
  std::vector<Entry> Entries() const;
  /// Value of the first entry with scalar key `key`; undefined when absent.
  YamlNode Child(const std::string& key) const;
  /// Follows a key path such as "lidar.p_lidar_in_imu_m[1]"; undefined when
  /// any step is missing.
  YamlNode FindPath(const std::string& path) const;

  /// Strict conversions of a plain (unquoted) scalar; false on any mismatch.
  bool AsBool(bool* value) const;
  bool AsInt64(int64_t* value) const;
  bool AsDouble(double* value) const;

  /// Short description for error messages: "a map", "a sequence of 2
  /// elements", "an empty value", or the quoted scalar text.
  std::string Describe() const;

 private:
  friend class YamlDocument;
  struct Impl;
  explicit YamlNode(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
};

/// Parses YAML text. On success `*root` is the document's root node (null for
/// an empty document). On a syntax error returns false and fills `*error_line`
/// (1-based, 0 if unknown) and `*error_message`. Never throws.
class YamlDocument {
 public:
  static bool Parse(const std::string& text,
                    YamlNode* root,
                    int* error_line,
                    std::string* error_message);
};

}  // namespace swarmlio::config
