#include "launcher/namespace_exec.hpp"

#include <unistd.h>

#include <cstdlib>
#include <stdexcept>

namespace auvrl::launcher {

bool in_private_namespace() {
  const char* inside = std::getenv("AUVRL_IN_NETNS");
  return inside != nullptr && std::string(inside) == "1";
}

std::vector<std::string> netns_prefix(const std::string& source_dir, const std::string& run_dir) {
  return {source_dir + "/scripts/netns.sh", "--pidfile", run_dir + "/netns.pid"};
}

void exec_in_namespace(std::vector<std::string> args) {
  if (args.empty()) throw std::runtime_error("exec_in_namespace: no command");
  setenv("AUVRL_IN_NETNS", "1", 1);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  execv(args[0].c_str(), argv.data());
  throw std::runtime_error("cannot run " + args[0]);
}

}  // namespace auvrl::launcher
