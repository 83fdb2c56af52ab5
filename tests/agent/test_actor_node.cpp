// The actor's demonstrations and expert labels, in process: auv_sim's server and the actor on
// one in-process bus (the server answers inside the actor's own lockstep waits), no learner (the
// policy is zero until weights arrive). A demonstration is driven by the demonstrator, its
// experience goes out like any other and it is not reported as an episode; expert labels are
// the expert's command in each transition's state.
#include <gtest/gtest.h>

#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "agent/actor_config.hpp"
#include "agent/actor_node.hpp"
#include "agent/pid_controller.hpp"
#include "common/channels.hpp"
#include "common/transport.hpp"
#include "sim/sim_server.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {
namespace {

class ActorDemonstrations : public ::testing::Test {
 protected:
  ActorDemonstrations()
      : model_(sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml")),
        bus_(transport::make_in_process_transport()),
        server_(model_, *bus_, server_config()) {
    transport::subscribe<auvrl_lcm::episode_report_t>(
        *bus_, channels::kEpisode,
        [this](const std::string&, const auvrl_lcm::episode_report_t&) { ++reports_; });
    transport::subscribe<auvrl_lcm::experience_batch_t>(
        *bus_, channels::kExperience,
        [this](const std::string&, const auvrl_lcm::experience_batch_t& m) {
          transitions_ += m.num_transitions;
          batches_.push_back(m);
        });
  }
  static sim::SimServerConfig server_config() {
    sim::SimServerConfig c;
    c.heartbeat_period_s = 3600;
    return c;
  }
  ActorNodeConfig config(double fraction) const {
    ActorNodeConfig c;
    c.vehicle = model_.facts();
    task::apply_vehicle(c.vehicle, c.task);
    c.task.layout = task::StateLayout::kExtendedThrust;
    c.task.reward = task::RewardKind::kShaped;
    c.task.max_steps = 150;  // 15 s: the PID reaches most way-points of a smaller box in that
    c.task.goal_min_ned_m = Eigen::Vector3d(-4.0, -4.0, 3.0);
    c.task.goal_max_ned_m = Eigen::Vector3d(4.0, 4.0, 7.0);
    c.noise = ExplorationNoise::Kind::kNone;
    c.initial_beta_m = 0.5;
    c.weights_request_period_s = 3600;
    c.demonstration_fraction = fraction;
    if (fraction > 0) c.demonstrator = std::make_shared<PidController>(model_);
    return c;
  }

  sim::VehicleModel model_;
  std::unique_ptr<transport::Transport> bus_;
  sim::SimServer server_;
  std::ostringstream log_;
  int reports_ = 0;
  std::int64_t transitions_ = 0;
  std::vector<auvrl_lcm::experience_batch_t> batches_;
};

TEST_F(ActorDemonstrations, AllDemonstrationsReachAndSendExperienceButNoReports) {
  ActorNode node(config(1.0), *bus_, log_);
  int reached = 0;
  std::int64_t steps = 0;
  for (int i = 0; i < 10; ++i) {
    const EpisodeSummary s = node.run_one_episode();
    EXPECT_TRUE(node.last_was_demonstration());
    reached += s.success ? 1 : 0;
    steps += s.length_steps;
  }
  bus_->drain();
  // The zero policy reaches nothing in a box this size; the PID does.
  EXPECT_GE(reached, 8);
  EXPECT_EQ(node.counters().demonstrations, 10);
  EXPECT_EQ(reports_, 0);
  EXPECT_EQ(transitions_, steps);
}

TEST_F(ActorDemonstrations, NoneByDefaultAndTheirShareOtherwise) {
  {
    ActorNode node(config(0.0), *bus_, log_);
    int reached = 0;
    for (int i = 0; i < 5; ++i) reached += node.run_one_episode().success ? 1 : 0;
    bus_->drain();
    EXPECT_EQ(reached, 0);  // the policy before any weights: zero thrust
    EXPECT_EQ(node.counters().demonstrations, 0);
    EXPECT_EQ(reports_, 5);
  }
  reports_ = 0;
  ActorNodeConfig c = config(0.3);
  c.task.max_steps = 5;  // only the share is counted here
  ActorNode node(c, *bus_, log_);
  const int n = 400;
  for (int i = 0; i < n; ++i) node.run_one_episode();
  bus_->drain();
  const std::int64_t demonstrations = node.counters().demonstrations;
  EXPECT_NEAR(static_cast<double>(demonstrations) / n, 0.3, 0.07);
  EXPECT_EQ(reports_, n - demonstrations);
}

TEST_F(ActorDemonstrations, AFractionWithoutADemonstratorIsAnError) {
  ActorNodeConfig c = config(0.0);
  c.demonstration_fraction = 0.5;
  EXPECT_THROW(ActorNode(c, *bus_, log_), std::invalid_argument);
  c.demonstration_fraction = 1.5;
  c.demonstrator = std::make_shared<PidController>(model_);
  EXPECT_THROW(ActorNode(c, *bus_, log_), std::invalid_argument);
}

// Expert labels: a second PID, asked in every state but never driving. With the PID also
// driving (demonstrations, no noise) each label must equal the action taken in that state:
// labels belong to x_t (not x_t+1) and the expert restarts with every episode.
TEST_F(ActorDemonstrations, ExpertLabelsAreThePidsCommandInEachState) {
  ActorNodeConfig c = config(1.0);
  c.expert_labels = true;
  c.expert = std::make_shared<PidController>(model_);
  ActorNode node(c, *bus_, log_);
  for (int i = 0; i < 3; ++i) node.run_one_episode();
  bus_->drain();
  ASSERT_FALSE(batches_.empty());
  std::int64_t labels = 0;
  for (const auto& m : batches_) {
    ASSERT_EQ(m.expert_rows, m.num_transitions);
    ASSERT_EQ(static_cast<int>(m.expert_actions.size()), m.num_transitions);
    for (int i = 0; i < m.num_transitions; ++i) {
      for (int j = 0; j < m.action_dim; ++j) {
        ASSERT_EQ(m.expert_actions[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)],
                  m.actions[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)])
            << "step " << m.step_index[static_cast<std::size_t>(i)] << " thruster " << j;
      }
      ++labels;
    }
  }
  EXPECT_EQ(labels, transitions_);

  // Off: no labels in the messages. On without an expert: an error.
  batches_.clear();
  ActorNode plain(config(0.0), *bus_, log_);
  plain.run_one_episode();
  bus_->drain();
  ASSERT_FALSE(batches_.empty());
  for (const auto& m : batches_) {
    EXPECT_EQ(m.expert_rows, 0);
    EXPECT_TRUE(m.expert_actions.empty());
  }
  ActorNodeConfig no_expert = config(0.0);
  no_expert.expert_labels = true;
  EXPECT_THROW(ActorNode(no_expert, *bus_, log_), std::invalid_argument);
}

TEST(ActorConfigFile, ReadsDemonstrationsExpertLabelsAndTheVehicle) {
  const std::string path = testing::TempDir() + "actor_demonstrations.yaml";
  const auto write = [&](const std::string& fraction) {
    std::ofstream(path) << "vehicle: ../vehicles/nessie7.yaml\nactor:\n  demonstration_fraction: "
                        << fraction << "\n  expert_labels: true\n";
  };
  write("0.25");
  ActorNodeConfig c;
  std::string vehicle;
  read_actor_config_file(path, c, &vehicle);
  EXPECT_DOUBLE_EQ(c.demonstration_fraction, 0.25);
  EXPECT_TRUE(c.expert_labels);
  // Resolved against the run file's folder, as the launcher does.
  EXPECT_NE(vehicle.find("vehicles/nessie7.yaml"), std::string::npos);
  EXPECT_NE(vehicle, "../vehicles/nessie7.yaml");
  write("1.5");
  try {
    read_actor_config_file(path, c, &vehicle);
    FAIL() << "a fraction of 1.5 was accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("demonstration_fraction"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::remove(path.c_str());
}

}  // namespace
}  // namespace auvrl::agent
