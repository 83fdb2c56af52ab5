// What the fine-tuning's tests share: the fast preset's task on the Nessie VII model, and the
// committed policy trained for it.
#pragma once

#include <string>

#include "agent_test_util.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/mlp.hpp"
#include "common/nn/serialize.hpp"
#include "common/task/task.hpp"

namespace auvrl::tuning::test {

/// The fast preset's layout (the extended state with the realised thrust) on Nessie VII.
inline task::TaskConfig fast_task() {
  task::TaskConfig t;
  t.layout = task::StateLayout::kExtendedThrust;
  task::apply_vehicle(test_support::nessie().facts(), t);
  return t;
}

/// config/policies/fast.nn.
inline nn::Mlp committed_policy() {
  return nn::network_from_bytes(nn::read_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn"),
                                1);
}

}  // namespace auvrl::tuning::test
