// The actor's demonstrations and expert labels, in process: auv_sim's server and the actor on
// one in-process bus (the server answers inside the actor's own lockstep waits), no learner (the
// policy is zero until weights arrive). A demonstration is driven by the demonstrator, its
// experience goes out like any other and it is not reported as an episode; expert labels are
// the expert's command in each transition's state. Randomised episodes (task.randomise) reach
// the simulator and leave the way-points alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <cmath>
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
        [this](const std::string&, const auvrl_lcm::episode_report_t& m) {
          ++reports_;
          report_conditions_.push_back(m.conditions);
        });
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
  std::vector<std::int32_t> report_conditions_;
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

// A fault drawn by the actor reaches auv_sim: the PID drives (so every thruster is asked for
// thrust), and the weak thruster's realised thrust (in the extended_thrust state) stays at zero
// for the whole episode. The way-points are those of an actor that randomises nothing.
TEST_F(ActorDemonstrations, RandomisedEpisodesReachTheSimulatorAndLeaveTheGoalsAlone) {
  const int episodes = 6;
  const auto goals_of = [&](const ActorNodeConfig& c, std::vector<int>* fault_thrusters) {
    batches_.clear();
    ActorNode node(c, *bus_, log_);
    for (int i = 0; i < episodes; ++i) {
      node.run_one_episode();
      if (fault_thrusters) fault_thrusters->push_back(node.last_conditions().fault_thruster);
    }
    bus_->drain();
    std::vector<std::vector<float>> goals;
    for (const auto& m : batches_) goals.push_back(m.goal_ned_m.front());
    return goals;
  };
  ActorNodeConfig plain = config(1.0);
  plain.task.max_steps = 40;
  ActorNodeConfig randomised = plain;
  randomised.task.randomise.fault_probability = 1.0;
  randomised.task.randomise.fault_efficiency = task::Range(0.0, 0.0);
  randomised.task.randomise.current_probability = 0.5;
  randomised.task.randomise.model_probability = 0.5;
  randomised.task.randomise.thrust_scale = task::Range(0.7, 0.9);

  const auto plain_goals = goals_of(plain, nullptr);
  std::vector<int> faults;
  const auto randomised_goals = goals_of(randomised, &faults);
  EXPECT_EQ(randomised_goals, plain_goals);
  ASSERT_EQ(static_cast<int>(batches_.size()), episodes);  // one batch per 40-step episode
  const int n = plain.task.num_thrusters;
  for (int e = 0; e < episodes; ++e) {
    const auto& m = batches_[static_cast<std::size_t>(e)];
    const int weak = faults[static_cast<std::size_t>(e)];
    ASSERT_GE(weak, 0);
    double weak_sum = 0.0, others_max = 0.0;
    for (const auto& state : m.next_states) {
      for (int k = 0; k < n; ++k) {
        const double thrust = std::abs(state[static_cast<std::size_t>(m.state_dim - n + k)]);
        if (k == weak) {
          weak_sum += thrust;
        } else {
          others_max = std::max(others_max, thrust);
        }
      }
    }
    EXPECT_EQ(weak_sum, 0.0) << "episode " << e << ", thruster " << weak;
    EXPECT_GT(others_max, 0.05) << "episode " << e;
  }
  EXPECT_EQ(server_.vehicle(0)->thruster_efficiency[faults.back()], 0.0);

  // The policy's episodes report what was drawn.
  randomised.demonstration_fraction = 0.0;
  randomised.demonstrator.reset();
  ActorNode node(randomised, *bus_, log_);
  for (int i = 0; i < 4; ++i) node.run_one_episode();
  bus_->drain();
  ASSERT_EQ(report_conditions_.size(), 4u);
  EXPECT_EQ(static_cast<unsigned>(report_conditions_.back()), node.last_conditions().kinds);
  for (std::int32_t bits : report_conditions_) {
    EXPECT_TRUE(bits & auvrl_lcm::episode_report_t::CONDITION_FAULT);
  }
}

// The paper, fast and smooth presets randomise nothing (the paper's stays literal); robust.yaml
// turns every kind on.
TEST(ActorConfigFile, OnlyTheRobustPresetRandomisesEpisodes) {
  for (const std::string preset : {"paper", "fast", "robust"}) {
    ActorNodeConfig c;
    read_actor_config_file(std::string(AUVRL_CONFIG_DIR) + "/presets/" + preset + ".yaml", c);
    const task::EpisodeRandomisation& r = c.task.randomise;
    if (preset != "robust") {
      EXPECT_FALSE(r.any()) << preset;
      EXPECT_EQ(c.task.command_change_weight, 0.0) << preset;
      continue;
    }
    for (double p : {r.fault_probability, r.current_probability, r.varying_current_probability,
                     r.sensor_noise_probability, r.model_probability}) {
      EXPECT_GT(p, 0.0);
    }
    EXPECT_NO_THROW(c.task.validate());
  }
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
