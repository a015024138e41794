/**
 * @file tool_runner.h
 * @brief Runs a command-line tool as a user would, bounded in time: for the tool tests and the
 *        fuzz suite's subprocess cases.
 */
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace fdml_localization
{
namespace test
{
/// The outcome of one run.
struct ToolRun
{
  int code = -1;  ///< exit status; 124 when the time limit was reached, -1 when killed by a signal
  std::string out;
  std::string err;
};

/**
 * @brief Runs `EXE ARGS` (ARGS as shell words) under coreutils' timeout, capturing stdout and
 *        stderr in files of @p scratch_dir (which must exist).
 */
inline ToolRun runTool(const std::string& exe, const std::string& args, const std::string& scratch_dir,
                       int timeout_seconds = 60)
{
  const std::string out_path = scratch_dir + "/tool_out.txt";
  const std::string err_path = scratch_dir + "/tool_err.txt";
  const std::string command = "timeout -k 5 " + std::to_string(timeout_seconds) + " " + exe + " " + args + " > " +
                              out_path + " 2> " + err_path + " < /dev/null";
  const int status = std::system(command.c_str());
  ToolRun run;
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::stringstream o;
  o << std::ifstream(out_path).rdbuf();
  std::stringstream e;
  e << std::ifstream(err_path).rdbuf();
  run.out = o.str();
  run.err = e.str();
  return run;
}

}  // namespace test
}  // namespace fdml_localization
