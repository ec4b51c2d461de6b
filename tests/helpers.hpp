#pragma once
// Shared test helpers: a fresh temporary folder, running a program and capturing its exit code and stderr.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace geomint::testing {

inline std::filesystem::path fresh_dir(const std::string& name) {
  auto d = std::filesystem::temp_directory_path() / ("geomint-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

struct ProgramResult {
  int exit_code;
  std::string err;
};

// Runs GEOMINT_BIN_DIR/program with args (a shell word list), stdout discarded.
inline ProgramResult run_program(const std::string& program, const std::string& args) {
  const auto errfile = fresh_dir("stderr") / "err.txt";
  const std::string cmd = std::string(GEOMINT_BIN_DIR) + "/" + program + " " + args + " > /dev/null 2> " + errfile.string();
  const int status = std::system(cmd.c_str());
  std::ifstream in(errfile);
  std::stringstream ss;
  ss << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, ss.str()};
}

inline std::size_t count_files(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for (auto it = std::filesystem::recursive_directory_iterator(dir); it != std::filesystem::recursive_directory_iterator(); ++it)
    if (it->is_regular_file()) ++n;
  return n;
}

}  // namespace geomint::testing
