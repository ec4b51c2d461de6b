#pragma once
// Command lines of the programs that take a system by name: --system picks it from the registry, and every
// parameter of that system becomes an option of its own (--alpha 0.2, --T 50, ...), listed by --help.
// Programs that sweep accept several values per parameter and run the Cartesian product.
#include <string>
#include <vector>

#include "geomint/cli.hpp"
#include "geomint/registry.hpp"

namespace geomint {

class SystemOptions {
 public:
  // Reads --system from argv (before the full parse, which needs the system's parameter list) and adds
  // --system plus one option per parameter to cli. `sweep`: several values per parameter allowed.
  SystemOptions(Cli& cli, int argc, char** argv, const std::string& default_system, bool sweep);

  const SystemInfo& system() const { return *system_; }
  // The system file it was read from (--system-file), or "" for a registry system.
  const std::string& system_file() const { return file_; }
  // After cli.parse: every combination of the given values (one ParamValues when nothing is swept), each
  // validated; the parameters given more than one value, in the system's order.
  std::vector<ParamValues> combinations() const;
  std::vector<std::string> swept() const;
  // The single combination (programs that do not sweep).
  ParamValues values() const;
  // Header lines: the system and every parameter (swept ones as lists).
  std::vector<std::pair<std::string, std::string>> header() const;
  // The schemes asked for (--schemes), or every scheme of the system when none.
  std::vector<std::string> schemes(const std::vector<std::string>& asked) const;

 private:
  const SystemInfo* system_ = nullptr;
  std::vector<std::vector<double>> given_;  // per parameter, in the system's order
  std::string file_;
  bool sweep_;
};

// The value of a swept parameter in a combination.
double param_value(const ParamValues& pv, const SystemInfo& sys, const std::string& name);

}  // namespace geomint
