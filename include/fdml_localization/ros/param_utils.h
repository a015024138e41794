/**
 * @file param_utils.h
 * @brief Helpers between ROS parameters and the core: XmlRpc parameter trees to
 *        core::ParamValue, and resolution of package:// resource paths.
 */
#pragma once

#include "fdml_localization/core/util/param_tree.h"

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <string>

namespace fdml_localization
{
/// Converts a parameter tree (struct -> map, array -> list, scalars; base64 and dates -> strings).
core::ParamValue fromXmlRpc(const XmlRpc::XmlRpcValue& value);

/// Every parameter under the node handle's namespace as one map (empty map when none).
core::ParamValue readParamTree(const ros::NodeHandle& nh);

/**
 * @brief Resolves a resource path: "package://pkg/rel/path" becomes the package's directory
 *        (found with ros::package, i.e. rospack on ROS_PACKAGE_PATH) joined with rel/path;
 *        "file:///abs" becomes "/abs"; anything else is returned unchanged.
 * @param[out] error set when the package is not found or the URL is malformed
 * @return the path, or "" on error
 */
std::string resolveResourcePath(const std::string& url, std::string* error);

}  // namespace fdml_localization
