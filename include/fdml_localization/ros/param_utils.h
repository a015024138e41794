/**
 * @file param_utils.h
 * @brief Helpers between ROS parameters and the core: XmlRpc parameter trees to
 *        core::ParamValue, and resolution of package:// resource paths.
 */
#pragma once

#include "fdml_localization/core/util/param_tree.h"

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace fdml_localization
{
/// Converts a parameter tree (struct -> map, array -> list, scalars; base64 and dates -> strings).
core::ParamValue fromXmlRpc(const XmlRpc::XmlRpcValue& value);

/// Every parameter under the node handle's namespace as one map (empty map when none).
core::ParamValue readParamTree(const ros::NodeHandle& nh);

/**
 * @brief Typed reads of a node's private parameters, given as a tree (readParamTree(), or an
 *        in-memory tree in tests): the one place where the node's parameter types are checked.
 *        A value of the wrong type is an error naming the parameter and the expected type, e.g.
 *        "~resolution: expected an integer, got a string (\"abc\")", and leaves the target (its
 *        default) unchanged; so is an integer out of the target's range or a fractional number
 *        given for an integer. Allowed ranges are checked by the caller (the parameters'
 *        validate()).
 */
class ParamReader
{
public:
  /// @param errors where type errors are appended (must outlive the reader)
  ParamReader(const core::ParamValue& tree, std::vector<std::string>* errors);

  /// True when the parameter is set.
  bool has(const std::string& name) const;
  /// Each read returns true when the parameter is set and of the right type (then stored).
  bool read(const std::string& name, bool* value);
  bool read(const std::string& name, int* value);  ///< an integer (an integral number is accepted)
  bool read(const std::string& name, long* value);
  bool read(const std::string& name, double* value);  ///< a number (an integer is accepted)
  bool read(const std::string& name, std::string* value);
  bool read(const std::string& name, std::vector<double>* value);  ///< a list of numbers

private:
  bool readInteger(const std::string& name, std::int64_t min, std::int64_t max, std::int64_t* value);
  /// The parameter when set and accepted by @p accept; nullptr when unset, or (an error) rejected.
  const core::ParamValue* typed(const std::string& name, const std::function<bool(const core::ParamValue&)>& accept,
                                const std::string& expected);
  void typeError(const std::string& name, const std::string& expected, const core::ParamValue& value);

  const core::ParamValue& tree_;
  std::vector<std::string>* errors_;
};

/**
 * @brief Resolves a resource path: "package://pkg/rel/path" becomes the package's directory
 *        (found with ros::package, i.e. rospack on ROS_PACKAGE_PATH) joined with rel/path;
 *        "file:///abs" becomes "/abs"; anything else is returned unchanged.
 * @param[out] error set when the package is not found or the URL is malformed
 * @return the path, or "" on error
 */
std::string resolveResourcePath(const std::string& url, std::string* error);

}  // namespace fdml_localization
