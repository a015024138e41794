#include "fdml_localization/core/util/param_tree.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace fdml_localization
{
namespace core
{
ParamValue ParamValue::fromBool(bool value)
{
  ParamValue v;
  v.type_ = Type::Bool;
  v.bool_ = value;
  return v;
}

ParamValue ParamValue::fromInt(std::int64_t value)
{
  ParamValue v;
  v.type_ = Type::Int;
  v.int_ = value;
  return v;
}

ParamValue ParamValue::fromDouble(double value)
{
  ParamValue v;
  v.type_ = Type::Double;
  v.double_ = value;
  return v;
}

ParamValue ParamValue::fromString(const std::string& value)
{
  ParamValue v;
  v.type_ = Type::String;
  v.string_ = value;
  return v;
}

ParamValue ParamValue::makeList()
{
  ParamValue v;
  v.type_ = Type::List;
  return v;
}

ParamValue ParamValue::makeMap()
{
  ParamValue v;
  v.type_ = Type::Map;
  return v;
}

void ParamValue::append(ParamValue value)
{
  if (type_ == Type::Nil)
  {
    type_ = Type::List;
  }
  items_.push_back(std::move(value));
}

void ParamValue::set(const std::string& key, ParamValue value)
{
  if (type_ == Type::Nil)
  {
    type_ = Type::Map;
  }
  for (auto& entry : entries_)
  {
    if (entry.first == key)
    {
      entry.second = std::move(value);
      return;
    }
  }
  entries_.emplace_back(key, std::move(value));
}

const ParamValue* ParamValue::find(const std::string& key) const
{
  for (const auto& entry : entries_)
  {
    if (entry.first == key)
    {
      return &entry.second;
    }
  }
  return nullptr;
}

const char* ParamValue::typeName(Type type)
{
  switch (type)
  {
    case Type::Nil:
      return "nothing";
    case Type::Bool:
      return "a boolean";
    case Type::Int:
      return "an integer";
    case Type::Double:
      return "a number";
    case Type::String:
      return "a string";
    case Type::List:
      return "a list";
    case Type::Map:
      return "a map";
  }
  return "?";
}

namespace
{
std::string formatNumber(double value)
{
  std::ostringstream out;
  out << value;
  return out.str();
}
}  // namespace

FieldReader::FieldReader(const ParamValue& node, std::string path, std::vector<std::string>* errors)
  : node_(node), path_(std::move(path)), errors_(errors)
{
  if (node_.type() != ParamValue::Type::Nil && !node_.isMap())
  {
    errors_->push_back((path_.empty() ? std::string("<root>") : path_) + ": must be a map, got " +
                       ParamValue::typeName(node_.type()));
  }
}

std::string FieldReader::pathOf(const std::string& key) const
{
  return path_.empty() ? key : path_ + "." + key;
}

void FieldReader::error(const std::string& key, const std::string& message)
{
  errors_->push_back(pathOf(key) + ": " + message);
}

const ParamValue* FieldReader::lookup(const std::string& key, bool required)
{
  known_.push_back(key);
  const ParamValue* value = node_.find(key);
  if (value == nullptr && required)
  {
    error(key, "required key is missing");
  }
  return value;
}

bool FieldReader::has(const std::string& key)
{
  return lookup(key, false) != nullptr;
}

const ParamValue* FieldReader::child(const std::string& key, bool required)
{
  return lookup(key, required);
}

bool FieldReader::number(const std::string& key, double* out, double min, double max, bool required)
{
  const ParamValue* value = lookup(key, required);
  if (value == nullptr)
  {
    return false;
  }
  if (!value->isNumber())
  {
    error(key, std::string("must be a number, got ") + ParamValue::typeName(value->type()));
    return false;
  }
  const double v = value->asDouble();
  if (!std::isfinite(v) || v < min || v > max)
  {
    error(key, "must be in [" + formatNumber(min) + ", " + formatNumber(max) + "], got " + formatNumber(v));
    return false;
  }
  *out = v;
  return true;
}

bool FieldReader::integer(const std::string& key, std::int64_t* out, std::int64_t min, std::int64_t max, bool required)
{
  const ParamValue* value = lookup(key, required);
  if (value == nullptr)
  {
    return false;
  }
  if (value->type() != ParamValue::Type::Int)
  {
    error(key, std::string("must be an integer, got ") + ParamValue::typeName(value->type()));
    return false;
  }
  if (value->asInt() < min || value->asInt() > max)
  {
    error(key, "must be in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " +
                   std::to_string(value->asInt()));
    return false;
  }
  *out = value->asInt();
  return true;
}

bool FieldReader::boolean(const std::string& key, bool* out, bool required)
{
  const ParamValue* value = lookup(key, required);
  if (value == nullptr)
  {
    return false;
  }
  if (value->type() != ParamValue::Type::Bool)
  {
    error(key, std::string("must be true or false, got ") + ParamValue::typeName(value->type()));
    return false;
  }
  *out = value->asBool();
  return true;
}

bool FieldReader::string(const std::string& key, std::string* out, bool required,
                         const std::vector<std::string>& allowed)
{
  const ParamValue* value = lookup(key, required);
  if (value == nullptr)
  {
    return false;
  }
  if (value->type() != ParamValue::Type::String)
  {
    error(key, std::string("must be a string, got ") + ParamValue::typeName(value->type()));
    return false;
  }
  if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), value->asString()) == allowed.end())
  {
    std::string list;
    for (const auto& a : allowed)
    {
      list += (list.empty() ? "" : ", ") + a;
    }
    error(key, "must be one of {" + list + "}, got '" + value->asString() + "'");
    return false;
  }
  *out = value->asString();
  return true;
}

void FieldReader::finish()
{
  for (const auto& entry : node_.entries())
  {
    if (std::find(known_.begin(), known_.end(), entry.first) == known_.end())
    {
      errors_->push_back(pathOf(entry.first) + ": unknown key");
    }
  }
}

}  // namespace core
}  // namespace fdml_localization
