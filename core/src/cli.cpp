#include "geomint/cli.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstdio>
#include <iostream>
#include <set>
#include <unistd.h>

#include "geomint/budget.hpp"
#include "geomint/error.hpp"
#include "geomint/io.hpp"
#include "geomint/record.hpp"
#include "geomint/sweep.hpp"

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
    // No short options: a value that starts with '-' is a value, after a several-value option too ("--q 0 -0.3"
    // would otherwise end the values at "-0.3" and read it as an option). A word like "-x" is then a stray word.
    const po::parsed_options parsed = po::command_line_parser(argc, argv)
                                          .options(all)
                                          .positional(positional)
                                          .style(po::command_line_style::unix_style ^ po::command_line_style::allow_short)
                                          .run();
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
    // An option that needs a value and has none takes the next word whatever it is: "--schemes --out x" would read
    // "--out" as a scheme and x as a stray word, or run with x silently ignored. A value that names an option is
    // refused as that. Names given twice in one list ("--schemes la la") would repeat rows; numbers may repeat (a
    // vector such as --q 0 0).
    for (const auto& o : parsed.options) {
      if (o.string_key == "geomint-positional") continue;
      std::set<std::string> words;
      for (const auto& v : o.value) {
        const std::string name = v.size() > 2 && v.compare(0, 2, "--") == 0 ? v.substr(2, v.find('=') - 2) : "";
        if (!name.empty() && all.find_nothrow(name, false))
          throw InputError("option '--" + o.string_key + "' has no value before the option '" + one_line(v) +
                           "' (give its values after it, or leave it out for its default)");
        char* end = nullptr;
        (void)std::strtod(v.c_str(), &end);
        const bool number = !v.empty() && end == v.c_str() + v.size();
        if (!number && !words.insert(v).second)
          throw InputError("'" + one_line(v) + "' is given twice to --" + o.string_key);
      }
    }
    po::store(parsed, vm);
    if (vm.count("help")) {
      if (Sweep::launcher_rank() == 0) std::cout << program << ": " << summary << "\n\n" << options << "\n";
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

std::string one_line(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '\n' ? std::string("\\n") : c == '\r' ? std::string("\\r") : std::string(1, c);
  return out;
}

void print_line(const std::string& text) {
  const std::string line = text + '\n';
  for (std::size_t done = 0; done < line.size();) {
    const ssize_t n = ::write(2, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

namespace {
// The name a line starts with: the program's, and on an MPI rank other than 0 the rank's too.
std::string speaker() {
  const int rank = Sweep::launcher_rank();
  return rank == 0 ? g_program : g_program + " (rank " + std::to_string(rank) + ")";
}
}  // namespace

void report_missing(const std::string& context, const std::string& what) {
  std::string line = speaker() + ": " + context + ": " + what + " (recorded as a missing value)";
  for (char& c : line)
    if (c == '\n') c = ' ';
  print_line(line);
}

int guarded_main(const std::string& program, const std::function<int()>& body) {
  g_program = program;
  // Rank 0 speaks for the run. An input error is met identically by every rank (each validates the same command
  // line), so only rank 0 reports it: one line in all under mpiexec. Any other error may be one rank's own, so
  // the rank that meets it reports it, named. (A memory check refused on one rank's machine alone is the one
  // input error that can differ: that rank ends silently, and its launcher reports its exit status.)
  const bool root = Sweep::launcher_rank() == 0;
  if (root) handle_interrupts();
  // The run's outputs (OutputRun, started by prepare_output_dir) move into place only when the body succeeds;
  // any other way out discards them, and the previous outputs stay.
  auto discard = [] {
    if (OutputRun* r = OutputRun::current()) r->discard();
  };
  // The outcome is final once it is decided and said: an interrupt after it (Open MPI ending this rank because
  // another exited first with the agreed status) must not add a second line about the same run. The line and the
  // settling happen with interrupts held, so one arriving in between is acted on after, silently.
  auto settle = [](int status, const std::string& line = {}) {
    interrupts_after_outcome(status, [&] {
      if (!line.empty()) print_line(line);
    });
    return status;
  };
  // A rank that fails alone under MPI ends the others (which would otherwise wait for it forever).
  auto fail = [&](int status, const std::string& line = {}) {
    settle(status, line);
    Sweep::abort_all(status);
    return status;
  };
  try {
    const int status = body();
    if (OutputRun* r = OutputRun::current()) {
      if (status == 0)
        r->commit();
      else
        r->discard();
    }
    return status == 0 ? settle(0) : fail(status);
  } catch (const OtherRankDone&) {
    return settle(0);
  } catch (const InputError& e) {
    discard();
    // Before MPI starts every rank is validating the same command line; after it (a sweep past
    // prepare_output_dir) an input error can be this rank's alone, unless it is the folder's agreed outcome.
    const bool agreed = dynamic_cast<const OutputFolderRefused*>(&e) != nullptr;
    const std::string line =
        root || (!agreed && Sweep::started()) ? speaker() + ": error: " + one_line(e.what()) : std::string();
    return agreed ? settle(2, line) : fail(2, line);
  } catch (const NumericalFailure& e) {
    discard();
    return fail(3, speaker() + ": " + one_line(e.what()));
  } catch (const std::exception& e) {
    discard();
    return fail(1, speaker() + ": error: " + one_line(e.what()));
  }
}

}  // namespace geomint
