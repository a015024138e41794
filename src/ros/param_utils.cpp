#include "fdml_localization/ros/param_utils.h"

#include <ros/package.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace fdml_localization
{
core::ParamValue fromXmlRpc(const XmlRpc::XmlRpcValue& value)
{
  // XmlRpcValue's typed accessors are non-const; a copy shares the (reference counted) data.
  XmlRpc::XmlRpcValue v = value;
  switch (v.getType())
  {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return core::ParamValue::fromBool(static_cast<bool>(v));
    case XmlRpc::XmlRpcValue::TypeInt:
      return core::ParamValue::fromInt(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return core::ParamValue::fromDouble(static_cast<double>(v));
    case XmlRpc::XmlRpcValue::TypeString:
      return core::ParamValue::fromString(static_cast<std::string>(v));
    case XmlRpc::XmlRpcValue::TypeArray: {
      core::ParamValue list = core::ParamValue::makeList();
      for (int i = 0; i < v.size(); ++i)
      {
        list.append(fromXmlRpc(v[i]));
      }
      return list;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      core::ParamValue map = core::ParamValue::makeMap();
      for (auto it = v.begin(); it != v.end(); ++it)
      {
        map.set(it->first, fromXmlRpc(it->second));
      }
      return map;
    }
    case XmlRpc::XmlRpcValue::TypeDateTime:
    case XmlRpc::XmlRpcValue::TypeBase64:
      return core::ParamValue::fromString(v.toXml());
    case XmlRpc::XmlRpcValue::TypeInvalid:
      break;
  }
  return core::ParamValue();
}

core::ParamValue readParamTree(const ros::NodeHandle& nh)
{
  XmlRpc::XmlRpcValue tree;
  if (!nh.getParam(nh.getNamespace(), tree) || tree.getType() != XmlRpc::XmlRpcValue::TypeStruct)
  {
    return core::ParamValue::makeMap();
  }
  return fromXmlRpc(tree);
}

namespace
{
/// The value's type, and the value itself when a scalar, for error messages.
std::string describeValue(const core::ParamValue& value)
{
  std::ostringstream out;
  out << core::ParamValue::typeName(value.type());
  switch (value.type())
  {
    case core::ParamValue::Type::Bool:
      out << " (" << (value.asBool() ? "true" : "false") << ")";
      break;
    case core::ParamValue::Type::Int:
      out << " (" << value.asInt() << ")";
      break;
    case core::ParamValue::Type::Double:
      out << " (" << value.asDouble() << ")";
      break;
    case core::ParamValue::Type::String:
      out << " (\"" << value.asString() << "\")";
      break;
    default:
      break;
  }
  return out.str();
}
}  // namespace

ParamReader::ParamReader(const core::ParamValue& tree, std::vector<std::string>* errors) : tree_(tree), errors_(errors)
{}

bool ParamReader::has(const std::string& name) const
{
  return tree_.find(name) != nullptr;
}

void ParamReader::typeError(const std::string& name, const std::string& expected, const core::ParamValue& value)
{
  errors_->push_back("~" + name + ": expected " + expected + ", got " + describeValue(value));
}

const core::ParamValue* ParamReader::typed(const std::string& name,
                                           const std::function<bool(const core::ParamValue&)>& accept,
                                           const std::string& expected)
{
  const core::ParamValue* v = tree_.find(name);
  if (v != nullptr && !accept(*v))
  {
    typeError(name, expected, *v);
    return nullptr;
  }
  return v;
}

bool ParamReader::read(const std::string& name, bool* value)
{
  const auto* v = typed(
      name, [](const core::ParamValue& p) { return p.type() == core::ParamValue::Type::Bool; },
      "a boolean (true or false)");
  if (v != nullptr)
  {
    *value = v->asBool();
  }
  return v != nullptr;
}

bool ParamReader::readInteger(const std::string& name, std::int64_t min, std::int64_t max, std::int64_t* value)
{
  // An integral number (e.g. 10.0) is accepted; the range check comes before the conversion.
  const auto in_range = [min, max](const core::ParamValue& p) {
    const double d = p.asDouble();
    return (p.type() == core::ParamValue::Type::Int && p.asInt() >= min && p.asInt() <= max) ||
           (p.type() == core::ParamValue::Type::Double && std::isfinite(d) && d == std::floor(d) &&
            d >= static_cast<double>(min) && d <= static_cast<double>(max));
  };
  const auto* v = typed(name, in_range, "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  if (v != nullptr)
  {
    *value = v->type() == core::ParamValue::Type::Int ? v->asInt() : static_cast<std::int64_t>(v->asDouble());
  }
  return v != nullptr;
}

bool ParamReader::read(const std::string& name, int* value)
{
  std::int64_t v = 0;
  const bool ok = readInteger(name, std::numeric_limits<int>::min(), std::numeric_limits<int>::max(), &v);
  *value = ok ? static_cast<int>(v) : *value;
  return ok;
}

bool ParamReader::read(const std::string& name, long* value)
{
  std::int64_t v = 0;
  const bool ok = readInteger(name, std::numeric_limits<long>::min(), std::numeric_limits<long>::max(), &v);
  *value = ok ? static_cast<long>(v) : *value;
  return ok;
}

bool ParamReader::read(const std::string& name, double* value)
{
  const auto* v = typed(
      name, [](const core::ParamValue& p) { return p.isNumber(); }, "a number");
  if (v != nullptr)
  {
    *value = v->asDouble();
  }
  return v != nullptr;
}

bool ParamReader::read(const std::string& name, std::string* value)
{
  const auto* v = typed(
      name, [](const core::ParamValue& p) { return p.type() == core::ParamValue::Type::String; }, "a string");
  if (v != nullptr)
  {
    *value = v->asString();
  }
  return v != nullptr;
}

bool ParamReader::read(const std::string& name, std::vector<double>* value)
{
  const auto numbers_only = [](const core::ParamValue& p) {
    return p.isList() &&
           std::all_of(p.items().begin(), p.items().end(), [](const core::ParamValue& i) { return i.isNumber(); });
  };
  const auto* v = typed(name, numbers_only, "a list of numbers");
  if (v == nullptr)
  {
    return false;
  }
  value->clear();
  for (const core::ParamValue& item : v->items())
  {
    value->push_back(item.asDouble());
  }
  return true;
}

std::string resolveResourcePath(const std::string& url, std::string* error)
{
  const std::string package_prefix = "package://";
  const std::string file_prefix = "file://";
  if (url.rfind(file_prefix, 0) == 0)
  {
    return url.substr(file_prefix.size());
  }
  if (url.rfind(package_prefix, 0) != 0)
  {
    return url;
  }
  const std::string rest = url.substr(package_prefix.size());
  const std::size_t slash = rest.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 >= rest.size())
  {
    *error = "'" + url + "' is not of the form package://PACKAGE/PATH";
    return "";
  }
  const std::string package = rest.substr(0, slash);
  const std::string directory = ros::package::getPath(package);
  if (directory.empty())
  {
    *error = "package '" + package + "' of '" + url + "' was not found (is the workspace sourced?)";
    return "";
  }
  return directory + "/" + rest.substr(slash + 1);
}

}  // namespace fdml_localization
