// The machinery of the shapes compiled at run time (formula/jit.hpp) on a unit that compiles in a moment: compiled
// once into the cache and loaded, a unit that does not compile refused with the compiler's words and nothing left
// behind, and the path turned off. The shapes themselves: tests/formula/symbolic_shapes_at_run_time.test.cpp.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "geomint/formula/description.hpp"
#include "geomint/formula/formula_registry.hpp"
#include "geomint/formula/jit.hpp"
#include "geomint/formula/model.hpp"
#include "helpers.hpp"

using namespace geomint;
namespace fs = std::filesystem;

namespace {

formula::jit::Library probe(const std::string& name, const std::string& value) {
  formula::jit::Library library;
  library.name = name;
  library.what = "a test unit";
  library.units.push_back({"tests/formula/jit_probe.cpp.in", {{"GEOMINT_PROBE_VALUE", value}}, "", {}});
  return library;
}

std::size_t files_ending(const fs::path& dir, const std::string& suffix) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string f = e.path().filename().string();
    if (f.size() >= suffix.size() && f.compare(f.size() - suffix.size(), suffix.size(), suffix) == 0) ++n;
  }
  return n;
}

}  // namespace

TEST_CASE("shapes compiled at run time: a unit is compiled into the cache and loaded, and one that does not compile "
          "says why and leaves nothing",
          "[formula][jit]") {
  REQUIRE(formula::jit::enabled());
  const fs::path cache = testing::fresh_dir("jit-cache");
  const testing::ScopedEnv env("GEOMINT_SHAPE_CACHE", cache.string());
  REQUIRE(formula::jit::cache_directory() == cache.string());
  const std::string tag = std::to_string(::getpid());

  const auto f = reinterpret_cast<int (*)()>(formula::jit::symbol(probe("probe_" + tag, "42"), "geomint_jit_probe"));
  CHECK(f() == 42);
  CHECK(fs::exists(cache / ("probe_" + tag + ".so")));
  CHECK(fs::exists(cache / ("probe_" + tag + ".stamp")));
  CHECK(fs::exists(cache / ("probe_" + tag + ".0.d")));  // what it included: checked at the next process's load

  std::string message;
  try {
    formula::jit::symbol(probe("broken_" + tag, "no_such_name"), "geomint_jit_probe");
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  INFO(message);
  CHECK(message.find("compiling a test unit failed") != std::string::npos);
  CHECK(message.find("no_such_name") != std::string::npos);  // the compiler's own words, from its log
  CHECK(message.find(".log") != std::string::npos);
  CHECK_FALSE(fs::exists(cache / ("broken_" + tag + ".so")));
  CHECK(files_ending(cache, ".o") == 0);
  CHECK(files_ending(cache, ".tmp") == 0);
  fs::remove_all(cache);
}

TEST_CASE("shapes compiled at run time: turned off, a shape the build does not compile is the error naming shapes.def",
          "[formula][jit]") {
  const testing::ScopedEnv off("GEOMINT_SHAPE_JIT", "0");
  std::string why;
  CHECK_FALSE(formula::jit::enabled(&why));
  CHECK(why.find("GEOMINT_SHAPE_JIT=0") != std::string::npos);
  const auto model = formula::compile_model(formula::parse_system_file(
      "[system]\nname = five\ncoordinates = 5\n[parameters]\nT = 1\n[dynamics]\nL = (v1^2 + v2^2 + v3^2 + v4^2 + v5^2)/2 - q1^2\n"
      "[initial]\nq1 = 1\nq2 = 0\nq3 = 0\nq4 = 0\nq5 = 0\nv1 = 0\nv2 = 0\nv3 = 0\nv4 = 0\nv5 = 0\n",
      "five"));
  REQUIRE_FALSE(formula::formula_shape_compiled(5, 0, false));
  const std::string error = testing::error_of([&] { formula::formula_system_info(model); });
  INFO(error);
  CHECK(error.find("GEOMINT_FORMULA_SHAPE(5, 0, 0, 1)") != std::string::npos);
  CHECK(error.find("GEOMINT_SHAPE_JIT=0") != std::string::npos);
}
