// Helpers shared by the test suites: scratch folders, running the CLI, shared data lookup, thrown statuses.
#pragma once

#include "core/error.h"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace hsr::test {

/// The status of the hsr::Error that `fn()` throws; Status::Ok when it returns normally.
template <class F>
Status status_of(F&& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.status();
  }
  return Status::Ok;
}

/// A fresh scratch folder per test: <build>/test_tmp/<binary>/<name>, emptied first.
inline std::filesystem::path scratch_dir(const std::string& name) {
  std::filesystem::path p = std::filesystem::path(HSR_TEST_TMP_DIR) / name;
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

/// Path of a file in ../shared/data, or "" when it is absent (callers GTEST_SKIP with a message).
inline std::string shared_data(const std::string& file) {
  std::filesystem::path p = std::filesystem::path(HSR_SHARED_DATA_DIR) / file;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

/// Path of a file in ../shared/airborne, or "" when it is absent (callers GTEST_SKIP with a message).
inline std::string shared_airborne(const std::string& file) {
  std::filesystem::path p = std::filesystem::path(HSR_SHARED_AIRBORNE_DIR) / file;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// Runs the hsr CLI with the given arguments (a shell-quoted string) and captures its output.
inline CommandResult run_cli(const std::string& args) {
  const std::string cmd = std::string(HSR_CLI_PATH) + " " + args + " 2>&1";
  CommandResult r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline void write_file(const std::filesystem::path& p, const std::string& content) {
  std::ofstream out(p, std::ios::binary);
  out << content;
}

/// Number of entries in a folder (to check that a failed command left no file behind).
inline std::size_t count_entries(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace hsr::test
