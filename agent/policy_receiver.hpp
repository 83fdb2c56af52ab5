// The actor's side of the weights broadcast: turns a policy_weights_t into the policy the actor
// acts with, or refuses it. Anyone on the bus can publish weights (LCM has no authentication)
// and the checksum only catches damage, so everything is checked before anything is applied.
#pragma once

#include <auvrl_lcm/policy_weights_t.hpp>
#include <cstdint>
#include <memory>
#include <string>

#include "agent/controller.hpp"

namespace auvrl::agent {

/// What a weights message did.
enum class WeightsOutcome {
  kApplied,    ///< a new network (or the first one) is in place
  kRefreshed,  ///< same version as held: only the schedule fields were taken
  kRejected,   ///< refused (see the error): nothing of the message was applied
  /// A sound network whose sizes do not fit this actor's task: a learner of another vehicle or
  /// layout (see the error). Nothing was applied; no later message will fit either.
  kWrongSizes,
};

/// Holds the newest policy (and the learner's schedule fields) taken from weights messages.
class PolicyReceiver {
 public:
  PolicyReceiver(int state_dim, int num_thrusters, double initial_beta_m);

  /// Applies msg if every check passes: finite beta_m > 0 and updates_owed >= 0, version >= 0,
  /// num_bytes equal to the network's size, a network that parses (magic, format, sizes,
  /// CRC-32), fits the task (inputs, outputs, tanh output) and has only finite parameters.
  /// On kRejected or kWrongSizes, error says why and nothing changed.
  WeightsOutcome apply(const auvrl_lcm::policy_weights_t& msg, std::string& error);

  /// The policy, or nullptr before the first accepted weights.
  PolicyController* policy() { return policy_.get(); }
  std::int64_t version() const { return version_; }  ///< -1: none yet
  double beta_m() const { return beta_m_; }
  bool training_done() const { return training_done_; }
  double learner_backlog() const { return learner_backlog_; }
  std::int64_t applied() const { return applied_; }
  std::int64_t rejected() const { return rejected_; }

 private:
  int state_dim_;
  int num_thrusters_;
  std::unique_ptr<PolicyController> policy_;
  std::int64_t version_ = -1;
  double beta_m_;
  bool training_done_ = false;
  double learner_backlog_ = 0.0;
  std::int64_t applied_ = 0;
  std::int64_t rejected_ = 0;
};

}  // namespace auvrl::agent
