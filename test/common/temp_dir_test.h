// A gtest fixture owning a fresh temporary folder for each test, removed afterwards.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fdml_localization
{
namespace test
{
class TempDirTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("fdml_" + std::string(info->test_suite_name()) + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override
  {
    std::filesystem::remove_all(dir_);
  }
  /// The path of @p name in the folder.
  std::string file(const std::string& name) const
  {
    return (dir_ / name).string();
  }
  /// Writes @p bytes to @p name in the folder; returns its path.
  std::string write(const std::string& name, const std::string& bytes) const
  {
    std::ofstream(file(name), std::ios::binary) << bytes;
    return file(name);
  }

  std::filesystem::path dir_;
};

}  // namespace test
}  // namespace fdml_localization
