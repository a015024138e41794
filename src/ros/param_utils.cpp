#include "fdml_localization/ros/param_utils.h"

#include <ros/package.h>

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
