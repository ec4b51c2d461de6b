#pragma once
// Shared test helpers: a fresh temporary folder, the message an input error carries, running a program and capturing
// its exit code and stderr.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <sys/wait.h>

#include <catch2/catch.hpp>

#include "geomint/error.hpp"

namespace geomint::testing {

inline std::filesystem::path fresh_dir(const std::string& name) {
  auto d = std::filesystem::temp_directory_path() / ("geomint-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// A file's bytes ("" if it cannot be read), copied in blocks: the probe reads every program binary (46 MB each in
// the sanitizer build), where a character-by-character copy took most of a minute. Not by its size: /proc files
// report 0.
inline std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream out;
  if (in && in.peek() != std::ifstream::traits_type::eof()) out << in.rdbuf();
  return out.str();
}

// The message of the InputError that `f` throws ("" if none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

struct ProgramResult {
  int exit_code;
  std::string err, out;
};

// Runs GEOMINT_BIN_DIR/program with args (a shell word list), its stdout and stderr kept.
inline ProgramResult run_program(const std::string& program, const std::string& args) {
  const auto dir = fresh_dir("stderr");
  const std::string cmd = std::string(GEOMINT_BIN_DIR) + "/" + program + " " + args + " > " + (dir / "out.txt").string() +
                          " 2> " + (dir / "err.txt").string();
  const int status = std::system(cmd.c_str());
  auto read = [](const std::filesystem::path& f) {
    std::ifstream in(f);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read(dir / "err.txt"), read(dir / "out.txt")};
}

// Sets an environment variable for the scope, and puts back what was there.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

inline std::size_t count_files(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for (auto it = std::filesystem::recursive_directory_iterator(dir); it != std::filesystem::recursive_directory_iterator(); ++it)
    if (it->is_regular_file()) ++n;
  return n;
}

// The bad-input contract of every program: one line on stderr containing `expect`, exit 2, no output written.
inline void check_rejected(const std::string& program, const std::string& args, const std::string& expect) {
  const auto dir = fresh_dir("bad-input");
  const auto r = run_program(program, args + " --out " + (dir / "out").string());
  INFO(program << " " << args << " -> exit " << r.exit_code << ": " << r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.err.find(expect) != std::string::npos);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(!std::filesystem::exists(dir / "out"));
  std::filesystem::remove_all(dir);
}

}  // namespace geomint::testing
