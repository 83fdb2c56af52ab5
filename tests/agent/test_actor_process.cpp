// auv_actor's process logic in process: how finish_actor_config completes the node's
// configuration from the command line's extras and which combinations it refuses.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "agent/actor_process.hpp"

namespace auvrl::agent {
namespace {

const std::string kVehicle = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";

TEST(FinishActorConfig, VehicleIdDefaultsToTheActorId) {
  ActorNodeConfig config;
  config.actor_id = 3;
  ActorProcessOptions options;
  options.seed = 42;
  finish_actor_config(options, config);
  EXPECT_EQ(config.vehicle_id, 3);
  EXPECT_EQ(config.seed, 42u);
  EXPECT_FALSE(config.demonstrator);
  EXPECT_FALSE(config.expert);
}

TEST(FinishActorConfig, ExplicitVehicleIdWins) {
  ActorNodeConfig config;
  config.actor_id = 3;
  ActorProcessOptions options;
  options.vehicle_id = 7;
  finish_actor_config(options, config);
  EXPECT_EQ(config.vehicle_id, 7);
}

TEST(FinishActorConfig, TheVehicleDefaultsToNessieVii) {
  ActorNodeConfig config;
  config.demonstration_fraction = 0.5;
  finish_actor_config(ActorProcessOptions{}, config);
  EXPECT_EQ(config.vehicle.name, "nessie7");
  EXPECT_EQ(config.task.num_thrusters, 6);
  EXPECT_TRUE(config.demonstrator);
}

TEST(FinishActorConfig, TheVehicleFileDecidesTheTasksThrusters) {
  ActorNodeConfig config;
  config.task.num_thrusters = 6;  // whatever was there: the vehicle's facts replace it
  ActorProcessOptions options;
  options.vehicle_path = std::string(AUVRL_CONFIG_DIR) + "/vehicles/bluerov2_heavy.yaml";
  finish_actor_config(options, config);
  EXPECT_EQ(config.vehicle.name, "bluerov2_heavy");
  EXPECT_EQ(config.vehicle.num_thrusters(), 8);
  EXPECT_NE(config.vehicle.file_crc32, 0u);
  EXPECT_EQ(config.task.num_thrusters, 8);
  EXPECT_DOUBLE_EQ(config.task.max_thrust_n, 40.0);
  EXPECT_EQ(config.vehicle.source_file, options.vehicle_path);
}

TEST(FinishActorConfig, BuildsOnlyWhatIsAskedFor) {
  ActorNodeConfig config;
  config.demonstration_fraction = 0.25;
  ActorProcessOptions options;
  options.vehicle_path = kVehicle;
  finish_actor_config(options, config);
  EXPECT_TRUE(config.demonstrator);
  EXPECT_FALSE(config.expert);

  ActorNodeConfig labels;
  labels.expert_labels = true;
  finish_actor_config(options, labels);
  EXPECT_FALSE(labels.demonstrator);
  EXPECT_TRUE(labels.expert);
}

TEST(FinishActorConfig, InvalidTaskIsRefused) {
  ActorNodeConfig config;
  config.task.max_steps = 0;
  EXPECT_THROW(finish_actor_config(ActorProcessOptions{}, config), std::invalid_argument);
}

}  // namespace
}  // namespace auvrl::agent
