#include "geomint/cli.hpp"

#include <cstdio>
#include <iostream>
#include <set>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/record.hpp"

namespace geomint {

Cli::Cli(std::string program_, std::string summary_) : program(std::move(program_)), summary(std::move(summary_)) {
  options.add_options()("help", "print this help and exit")(
      "out", po::value<std::string>(&out)->default_value("out"), "output folder (created if missing)")(
      "no-budget", "run even when the planned work exceeds the time budget (memory and size limits stay)");
}

bool Cli::parse(int argc, char** argv) {
  po::variables_map vm;
  try {
    // No positional arguments: a stray word (a second value after a one-value option, a typo) is an error,
    // never silently dropped. Positional words are collected under a hidden name to name the first one.
    po::options_description all;
    all.add(options).add_options()("geomint-positional", po::value<std::vector<std::string>>());
    po::positional_options_description positional;
    positional.add("geomint-positional", -1);
    const po::parsed_options parsed = po::command_line_parser(argc, argv).options(all).positional(positional).run();
    for (const auto& o : parsed.options)
      if (o.string_key == "geomint-positional")
        throw InputError("unexpected argument '" + (o.original_tokens.empty() ? std::string() : o.original_tokens.front()) +
                         "': every value belongs to an option, and one-value options take one (see --help)");
    // An option given twice is an error, for every option (one value or several): "--alpha 0.1 --alpha 1"
    // is written "--alpha 0.1 1".
    std::set<std::string> seen;
    for (const auto& o : parsed.options)
      if (!seen.insert(o.string_key).second)
        throw InputError("option '--" + o.string_key + "' is given more than once (give all its values after one --" +
                         o.string_key + ")");
    po::store(parsed, vm);
    if (vm.count("help")) {
      std::cout << program << ": " << summary << "\n\n" << options << "\n";
      return false;
    }
    po::notify(vm);
    set_budget_enabled(vm.count("no-budget") == 0);
  } catch (const po::error& e) {
    throw InputError(std::string(e.what()) + " (see --help)");
  }
  return true;
}

namespace {
std::string g_program = "geomint";
}

const std::string& program_name() { return g_program; }

void report_missing(const std::string& context, const std::string& what) {
  std::string line = g_program + ": " + context + ": " + what + " (recorded as a missing value)";
  for (char& c : line)
    if (c == '\n') c = ' ';
  std::fprintf(stderr, "%s\n", line.c_str());
}

namespace {
// A message on one line whatever it quotes (a path may hold a newline).
std::string one_line(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '\n' ? std::string("\\n") : c == '\r' ? std::string("\\r") : std::string(1, c);
  return out;
}
}  // namespace

int guarded_main(const std::string& program, const std::function<int()>& body) {
  g_program = program;
  // The run's outputs (OutputRun, started by prepare_output_dir) move into place only when the body succeeds;
  // any other way out discards them, and the previous outputs stay.
  auto discard = [] {
    if (OutputRun* r = OutputRun::current()) r->discard();
  };
  try {
    const int status = body();
    if (OutputRun* r = OutputRun::current()) {
      if (status == 0)
        r->commit();
      else
        r->discard();
    }
    return status;
  } catch (const InputError& e) {
    discard();
    std::cerr << program << ": error: " << one_line(e.what()) << "\n";
    return 2;
  } catch (const NumericalFailure& e) {
    discard();
    std::cerr << program << ": " << one_line(e.what()) << "\n";
    return 3;
  } catch (const std::exception& e) {
    discard();
    std::cerr << program << ": error: " << one_line(e.what()) << "\n";
    return 1;
  }
}

}  // namespace geomint
