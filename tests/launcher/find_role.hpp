// A role of make_roles() by name, for the launcher's tests.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "launcher/supervisor.hpp"

namespace auvrl::test_support {

/// The role called `name`; throws std::runtime_error if there is none.
inline const launcher::RoleSpec& find_role(const std::vector<launcher::RoleSpec>& roles,
                                           const std::string& name) {
  for (const auto& r : roles) {
    if (r.name == name) return r;
  }
  throw std::runtime_error("no role " + name);
}

}  // namespace auvrl::test_support
