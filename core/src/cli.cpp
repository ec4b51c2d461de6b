#include "geomint/cli.hpp"

#include <iostream>

#include "geomint/error.hpp"

namespace geomint {

Cli::Cli(std::string program_, std::string summary_) : program(std::move(program_)), summary(std::move(summary_)) {
  options.add_options()("help", "print this help and exit")(
      "out", po::value<std::string>(&out)->default_value("out"), "output folder (created if missing)");
}

bool Cli::parse(int argc, char** argv) {
  po::variables_map vm;
  try {
    po::store(po::command_line_parser(argc, argv).options(options).run(), vm);
    if (vm.count("help")) {
      std::cout << program << ": " << summary << "\n\n" << options << "\n";
      return false;
    }
    po::notify(vm);
  } catch (const po::error& e) {
    throw InputError(std::string(e.what()) + " (see --help)");
  }
  return true;
}

int guarded_main(const std::string& program, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 2;
  } catch (const NumericalFailure& e) {
    std::cerr << program << ": " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << program << ": error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace geomint
