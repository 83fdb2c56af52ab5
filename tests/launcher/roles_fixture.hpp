// make_roles() for the launcher's tests: a role by name, and a fixture with a run context.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "launcher/supervisor.hpp"
#include "launcher/training.hpp"

namespace auvrl::test_support {

/// The role called `name`; throws std::runtime_error if there is none.
inline const launcher::RoleSpec& find_role(const std::vector<launcher::RoleSpec>& roles,
                                           const std::string& name) {
  for (const auto& r : roles) {
    if (r.name == name) return r;
  }
  throw std::runtime_error("no role " + name);
}

/// A run context for make_roles(): 2 actors on 4 CPUs, seed 3, a run directory with an empty
/// checkpoints/ (tests set what else they need in their SetUp, after this one's).
class RolesFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    ctx.options.bin_dir = "/bin";
    ctx.run_dir = make_temp_dir("auvrl_roles_");
    std::filesystem::create_directories(std::filesystem::path(ctx.run_dir) / "checkpoints");
    ctx.config_path = ctx.run_dir + "/config.yaml";
    ctx.rc.vehicle_path = "/v.yaml";
    ctx.rc.run.seed = 3;
    ctx.cpus = 4;
    ctx.actors = 2;
  }
  static const launcher::RoleSpec& find(const std::vector<launcher::RoleSpec>& roles,
                                        const std::string& name) {
    return find_role(roles, name);
  }
  launcher::RunContext ctx;
};

}  // namespace auvrl::test_support
