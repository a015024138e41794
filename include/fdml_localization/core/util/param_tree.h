/**
 * @file param_tree.h
 * @brief A small ROS-free tree of configuration values (the shape of a YAML document or of
 *        a ROS parameter namespace), so configuration parsing can be tested without ROS.
 */
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// One node of a configuration tree: nil, a scalar, a list or a map of named children.
class ParamValue
{
public:
  enum class Type
  {
    Nil,
    Bool,
    Int,
    Double,
    String,
    List,
    Map
  };

  ParamValue() = default;
  static ParamValue fromBool(bool value);
  static ParamValue fromInt(std::int64_t value);
  static ParamValue fromDouble(double value);
  static ParamValue fromString(const std::string& value);
  static ParamValue makeList();
  static ParamValue makeMap();

  Type type() const
  {
    return type_;
  }
  bool isNumber() const
  {
    return type_ == Type::Int || type_ == Type::Double;
  }
  bool isMap() const
  {
    return type_ == Type::Map;
  }
  bool isList() const
  {
    return type_ == Type::List;
  }

  bool asBool() const
  {
    return bool_;
  }
  std::int64_t asInt() const
  {
    return int_;
  }
  /// The value of an Int or Double node.
  double asDouble() const
  {
    return type_ == Type::Int ? static_cast<double>(int_) : double_;
  }
  const std::string& asString() const
  {
    return string_;
  }

  /// List items (empty unless a list).
  const std::vector<ParamValue>& items() const
  {
    return items_;
  }
  /// Map entries in insertion order (empty unless a map).
  const std::vector<std::pair<std::string, ParamValue>>& entries() const
  {
    return entries_;
  }

  /// Appends to a list (turns a nil node into a list).
  void append(ParamValue value);
  /// Sets a map entry, replacing an existing key (turns a nil node into a map).
  void set(const std::string& key, ParamValue value);
  /// The child named @p key of a map, nullptr when absent or not a map.
  const ParamValue* find(const std::string& key) const;

  /// A short name of the type for error messages ("a number", "a list", ...).
  static const char* typeName(Type type);

private:
  Type type_ = Type::Nil;
  bool bool_ = false;
  std::int64_t int_ = 0;
  double double_ = 0.0;
  std::string string_;
  std::vector<ParamValue> items_;
  std::vector<std::pair<std::string, ParamValue>> entries_;
};

/**
 * @brief Reads the fields of one map node, collecting every problem instead of stopping at the
 *        first: wrong types, values out of range, missing required keys, and (on finish())
 *        keys that no reader asked for. Every message starts with the full key path.
 */
class FieldReader
{
public:
  /**
   * @param node the map node to read (a nil node reads as an empty map)
   * @param path the node's key path for messages, e.g. "sensors[2]" ("" for the root)
   * @param errors where problems are appended (must outlive the reader)
   */
  FieldReader(const ParamValue& node, std::string path, std::vector<std::string>* errors);

  /// True when the key is present (and marks it as known).
  bool has(const std::string& key);
  /// Reads a number in [min, max]; keeps @p out when absent (an error when @p required).
  bool number(const std::string& key, double* out, double min, double max, bool required = false);
  /// Reads an integer in [min, max].
  bool integer(const std::string& key, std::int64_t* out, std::int64_t min, std::int64_t max, bool required = false);
  bool boolean(const std::string& key, bool* out, bool required = false);
  /// Reads a string; a non-empty @p allowed restricts it to those values.
  bool string(const std::string& key, std::string* out, bool required = false,
              const std::vector<std::string>& allowed = {});
  /// The child node (any type), nullptr when absent; marks the key as known.
  const ParamValue* child(const std::string& key, bool required = false);
  /// The key path of a child, for nested readers and messages.
  std::string pathOf(const std::string& key) const;
  /// Appends "path.key: message".
  void error(const std::string& key, const std::string& message);
  /// Reports every key of the node that was never asked for as unknown.
  void finish();

  const std::string& path() const
  {
    return path_;
  }

private:
  const ParamValue* lookup(const std::string& key, bool required);

  const ParamValue& node_;
  std::string path_;
  std::vector<std::string>* errors_;
  std::vector<std::string> known_;
};

}  // namespace core
}  // namespace fdml_localization
