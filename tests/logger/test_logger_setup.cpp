// auv_logger's process logic in process: --throttle texts become rules in order (a bad one
// refused), and types that cannot be loaded only cost the summary its type names.
#include <gtest/gtest.h>

#include <sstream>
#include <stdexcept>

#include "logger/logger_process.hpp"

namespace auvrl::logger {
namespace {

TEST(AddThrottleRules, AppendsInOrder) {
  LoggerConfig config;
  add_throttle_rules({"SIM_.*=0.5", "A=B=2"}, config);
  ASSERT_EQ(config.throttles.size(), 2u);
  EXPECT_EQ(config.throttles[0].pattern, "SIM_.*");
  EXPECT_DOUBLE_EQ(config.throttles[0].interval_s, 0.5);
  EXPECT_EQ(config.throttles[1].pattern, "A=B");  // split at the last '='
  EXPECT_DOUBLE_EQ(config.throttles[1].interval_s, 2.0);
}

TEST(AddThrottleRules, RefusesAMalformedRule) {
  LoggerConfig config;
  EXPECT_THROW(add_throttle_rules({"NO_INTERVAL"}, config), std::invalid_argument);
  EXPECT_THROW(add_throttle_rules({"X=soon"}, config), std::invalid_argument);
}

TEST(LoadSummarySchema, DefaultTypesLoad) {
  std::ostringstream log;
  const auto schema = load_summary_schema(default_types_dir(), log);
  ASSERT_NE(schema, nullptr);
  EXPECT_NE(schema->find_by_name("auvrl_lcm.vehicle_state_t"), nullptr);
  EXPECT_EQ(log.str(), "");
}

TEST(LoadSummarySchema, MissingDirectoryWarnsAndGivesNull) {
  std::ostringstream log;
  EXPECT_EQ(load_summary_schema("/nonexistent/auvrl/types", log), nullptr);
  EXPECT_NE(log.str().find("warning: types not loaded"), std::string::npos);
}

}  // namespace
}  // namespace auvrl::logger
