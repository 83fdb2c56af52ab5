#include "child_process.hpp"

#include <cstdlib>
#include <stdexcept>

namespace auvrl::test_support {

std::string bin_path(const std::string& name) { return std::string(AUVRL_BIN_DIR) + "/" + name; }

std::string make_temp_dir(const std::string& prefix) {
  std::string pattern = "/tmp/" + prefix + "XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  return pattern;
}

}  // namespace auvrl::test_support
