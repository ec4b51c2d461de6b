#pragma once
// Shapes compiled at their first use: the path for a formula system whose shape (n, m, holonomic) the build did not
// compile (shapes.def lists what it compiles). The same generated translation units the build makes for a listed
// shape are compiled with the build's own compiler and flags into a shared object, kept in a cache, and loaded into
// the running program. The schemes then run at the speed of a listed shape (the same code, at fixed sizes), after a
// compilation of about half a minute to two minutes of one core the first time, and a few milliseconds afterwards.
//
// Why not Eigen's dynamic sizes in the core: every step of every scheme works on fixed-size vectors, duals and
// Jacobians (no allocation in a step); at run-time sizes each dual operation and each solve allocates, and one
// generic core would serve both only by doubling what every scheme is written against.
//
// What runs: nothing a user typed reaches the compiler. Its arguments are the build's recorded flags, the cache's
// paths and the shape's three numbers, and it is started directly (posix_spawn, no shell). The shared object leaves
// the core's functions undefined and takes them from the running program (the programs export their symbols, the
// Python module is made global before the load), so there is one copy of every global: a Ctrl-C or a progress line
// reaches the code compiled here as it reaches the rest.
//
// The cache: $GEOMINT_SHAPE_CACHE, else shape-cache/ in the build folder. An object is used when the build's flags,
// the generated sources and every header they include are those it was compiled from (the compiler's dependency
// list, checked at each load), and recompiled otherwise; processes that want the same shape at once (mpiexec, ctest
// -j) take turns on a lock file and compile it once. GEOMINT_SHAPE_JIT=0 turns the path off (a shape not listed is
// then the InputError naming shapes.def, as before).
#include <string>
#include <utility>
#include <vector>

namespace geomint::formula::jit {

// One translation unit of a shared object: a template of the source tree (path relative to it) with @KEY@ replaced,
// then `appended` (the object's entry point: extern "C" and __attribute__((visibility("default"))), since everything
// else the object defines is hidden), compiled with the build's flags and then `options`.
struct Unit {
  std::string template_file;
  std::vector<std::pair<std::string, std::string>> substitutions;
  std::string appended;
  std::vector<std::string> options;
};

// A shared object: its name in the cache (letters, digits, '_'), what it is for messages ("the formula shape n = 7,
// m = 3"), its units, and whether it links GiNaC (the formulas' units).
struct Library {
  std::string name;
  std::string what;
  std::vector<Unit> units;
  bool links_formulas = false;
};

// Whether this build can compile shapes at run time (it recorded its flags, and GEOMINT_SHAPE_JIT is not 0), and if
// not, why.
bool enabled(std::string* why = nullptr);

// The address of `symbol` in the library: loaded once per process, from the cache when it is fresh there, compiled
// (with a line on stderr and a progress task) when not. Throws InputError when the path is off, and a
// std::runtime_error naming the compiler's log when a compilation fails.
void* symbol(const Library& library, const std::string& symbol);

// The cache folder in use.
std::string cache_directory();

}  // namespace geomint::formula::jit
