#pragma once
// Command lines for the experiment programs: Boost.Program_options with --help and --out on every
// program, and one place that turns errors into a one-line message and a nonzero exit.
#include <functional>
#include <string>

#include <boost/program_options.hpp>

namespace geomint {

namespace po = boost::program_options;

struct Cli {
  std::string program, summary;
  std::string out = "out";
  po::options_description options{"Options"};
  Cli(std::string program_, std::string summary_);
  // Returns false when --help was asked for (and printed). Throws InputError on bad options.
  bool parse(int argc, char** argv);
};

// Runs body; InputError -> "program: error: ..." and exit 2; NumericalFailure -> exit 3; other -> 1.
int guarded_main(const std::string& program, const std::function<int()>& body);

}  // namespace geomint
