// auvrl: the project's front command. Each subcommand parses its own options and calls the
// library that does the work (agent/evaluation.hpp for eval); adding one is adding a row to
// kSubcommands.
#include <exception>
#include <iostream>
#include <string>

#include "agent/evaluation.hpp"
#include "common/cli.hpp"

namespace {

#ifndef AUVRL_CONFIG_DIR
#error "AUVRL_CONFIG_DIR must be defined (agent/CMakeLists.txt sets it)"
#endif

/// `auvrl eval`: a policy file or the PID baseline on the evaluation scenarios.
int run_eval(int argc, const char* const* argv) {
  auvrl::agent::EvalRequest request;
  request.vehicle_path = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
  std::int64_t seed = 1;
  auvrl::cli::CommandLine cli(
      "auvrl eval",
      "Runs a controller on the evaluation scenarios in process (no noise, the full 70 s each)\n"
      "and writes DIR/summary.csv and DIR/trajectories/<scenario>_<episode>.csv.\n"
      "Scenarios: test1, test2 (facing away), fault (T1 at 10 %), current (0.3 m/s across),\n"
      "suite (random way-points of the training region), all.");
  cli.option("policy", &request.policy_path, "policy network file (nn format)");
  cli.option("controller", &request.controller, "policy or pid");
  cli.option("scenario", &request.scenario, "test1|test2|fault|current|suite|all");
  cli.option("out", &request.out_dir, "output directory (created)");
  cli.option("vehicle", &request.vehicle_path, "vehicle file");
  cli.option("layout", &request.layout,
             "paper|extended (default: from the policy's inputs, 12+n / 17+n)");
  cli.option("seed", &seed, "seed of the suite's way-points and the vehicle resets");
  cli.option("suite-episodes", &request.suite_episodes, "way-points in the suite");
  cli.option("suite-trajectories", &request.suite_trajectories,
             "trajectory files for the first N suite episodes (-1: all)");
  if (!cli.parse(argc, argv)) return 0;
  if (seed < 0) throw auvrl::cli::UsageError("option --seed: expected a value >= 0");
  request.seed = static_cast<std::uint64_t>(seed);
  auvrl::agent::run_eval_request(request, std::cout);
  return 0;
}

struct Subcommand {
  const char* name;
  const char* summary;
  int (*run)(int argc, const char* const* argv);
};

const Subcommand kSubcommands[] = {
    {"eval", "evaluate a policy or the PID baseline on test1/test2/fault/current/suite", run_eval},
};

void print_usage(std::ostream& out) {
  out << "usage: auvrl <command> [options]   (auvrl <command> --help for its options)\n\n"
         "commands:\n";
  for (const Subcommand& c : kSubcommands) {
    out << "  " << c.name << std::string(10 - std::string(c.name).size(), ' ') << c.summary << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    print_usage(std::cerr);
    return 2;
  }
  const std::string command = argv[1];
  if (command == "--help" || command == "-h" || command == "help") {
    print_usage(std::cout);
    return 0;
  }
  for (const Subcommand& c : kSubcommands) {
    if (command != c.name) continue;
    try {
      // The subcommand sees its options with argv[0] = the command's name.
      return c.run(argc - 1, argv + 1);
    } catch (const auvrl::cli::UsageError& e) {
      std::cerr << "auvrl " << command << ": " << e.what() << '\n';
      return 2;
    } catch (const std::invalid_argument& e) {  // a bad request (missing or wrong option)
      std::cerr << "auvrl " << command << ": " << e.what() << '\n';
      return 2;
    } catch (const std::exception& e) {
      std::cerr << "auvrl " << command << ": error: " << e.what() << '\n';
      return 1;
    }
  }
  std::cerr << "auvrl: unknown command '" << command << "'\n";
  print_usage(std::cerr);
  return 2;
}
