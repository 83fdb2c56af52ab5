// Randomised training episodes (task.randomise): off by default; each kind drawn with its
// probability, independently of the others, its values inside their ranges; the same seed gives
// the same conditions and the number of draws per episode is fixed, so that turning a kind on
// changes nothing the others draw; unusable settings are refused naming the key.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>

#include "common/config/table.hpp"
#include "common/config/yaml_config.hpp"
#include "common/task/randomisation.hpp"
#include "common/task/task.hpp"
#include "common/task/task_yaml.hpp"

namespace auvrl::task {
namespace {

constexpr int kThrusters = 6;
constexpr double kPi = 3.14159265358979323846;

EpisodeRandomisation everything() {
  EpisodeRandomisation r;
  r.fault_probability = 0.1;
  r.current_probability = 0.3;
  r.varying_current_probability = 0.5;
  r.sensor_noise_probability = 0.7;
  r.model_probability = 0.9;
  r.fault_efficiency = Range(0.0, 0.1);
  r.current_speed_mps = Range(0.1, 0.5);
  r.varying_current_sigma_mps = Range(0.02, 0.04);
  r.varying_current_time_constant_s = Range(20.0, 40.0);
  r.sensor_noise_scale = Range(0.5, 1.5);
  r.quadratic_damping_scale = Range(0.6, 1.5);
  r.added_mass_scale = Range(1.0, 1.5);
  r.mass_scale = Range(1.0, 1.2);
  r.thrust_scale = Range(0.7, 1.0);
  r.thruster_lag_time_constant_s = Range(0.3, 0.6);
  r.extra_buoyancy_n = Range(-5.0, 20.0);
  return r;
}

bool inside(double v, const Range& r) { return v >= r[0] && v <= r[1]; }

TEST(Randomisation, OffByDefault) {
  const TaskConfig task;
  EXPECT_FALSE(task.randomise.any());
  EXPECT_NO_THROW(task.validate());
  EXPECT_EQ(describe(task.randomise), "off");
  std::mt19937_64 rng(3);
  for (int i = 0; i < 1000; ++i) {
    const EpisodeConditions c = sample_conditions(task.randomise, kThrusters, rng);
    EXPECT_EQ(c.kinds, 0u);
    EXPECT_TRUE(c.thruster_efficiency.empty());
    EXPECT_TRUE(c.current_ned_mps.isZero());
    EXPECT_EQ(c.varying_current_sigma_mps, 0.0);
    EXPECT_EQ(c.noise_position_m + c.noise_attitude_rad + c.noise_velocity_mps +
                  c.noise_angular_rate_rad_s,
              0.0);
    EXPECT_EQ(c.quadratic_damping_scale, 1.0);
    EXPECT_EQ(c.mass_scale, 1.0);
    EXPECT_LT(c.thruster_lag_time_constant_s, 0.0);  // the file's
    EXPECT_EQ(c.extra_buoyancy_n, 0.0);
  }
}

TEST(Randomisation, EachKindComesWithItsProbabilityIndependently) {
  const EpisodeRandomisation r = everything();
  std::mt19937_64 rng(11);
  const int n = 40000;
  std::array<int, 5> count{};
  int fault_and_model = 0;
  for (int i = 0; i < n; ++i) {
    const unsigned kinds = sample_conditions(r, kThrusters, rng).kinds;
    for (unsigned bit = 0; bit < 5; ++bit) count[bit] += (kinds >> bit) & 1u;
    fault_and_model +=
        (kinds & EpisodeConditions::kFault) && (kinds & EpisodeConditions::kModel) ? 1 : 0;
  }
  const std::array<double, 5> p = {0.1, 0.3, 0.5, 0.7, 0.9};
  for (std::size_t k = 0; k < 5; ++k) {
    // Five standard deviations of a binomial share.
    EXPECT_NEAR(count[k] / double(n), p[k], 5.0 * std::sqrt(p[k] * (1 - p[k]) / n)) << k;
  }
  EXPECT_NEAR(fault_and_model / double(n), 0.1 * 0.9, 5.0 * std::sqrt(0.09 * 0.91 / n));
}

TEST(Randomisation, EveryValueLiesInItsRange) {
  EpisodeRandomisation r = everything();
  for (double* p : {&r.fault_probability, &r.current_probability, &r.varying_current_probability,
                    &r.sensor_noise_probability, &r.model_probability}) {
    *p = 1.0;
  }
  std::mt19937_64 rng(5);
  std::array<int, kThrusters> faults{};
  std::array<int, 4> quadrants{};
  for (int i = 0; i < 6000; ++i) {
    const EpisodeConditions c = sample_conditions(r, kThrusters, rng);
    ASSERT_EQ(c.kinds, 31u);
    ASSERT_GE(c.fault_thruster, 0);
    ASSERT_LT(c.fault_thruster, kThrusters);
    ++faults[static_cast<std::size_t>(c.fault_thruster)];
    ASSERT_EQ(c.thruster_efficiency.size(), static_cast<std::size_t>(kThrusters));
    EXPECT_TRUE(inside(c.thrust_scale, r.thrust_scale));
    for (int k = 0; k < kThrusters; ++k) {
      const double e = c.thruster_efficiency[static_cast<std::size_t>(k)];
      if (k == c.fault_thruster) {
        EXPECT_TRUE(inside(e / c.thrust_scale, r.fault_efficiency)) << e;
      } else {
        EXPECT_DOUBLE_EQ(e, c.thrust_scale);
      }
    }
    EXPECT_EQ(c.current_ned_mps.z(), 0.0);  // horizontal
    EXPECT_TRUE(inside(c.current_ned_mps.norm(), Range(0.1 - 1e-12, 0.5 + 1e-12)));
    ++quadrants[static_cast<std::size_t>(
                    (std::atan2(c.current_ned_mps.y(), c.current_ned_mps.x()) + kPi) / (kPi / 2)) %
                4];
    EXPECT_TRUE(inside(c.varying_current_sigma_mps, r.varying_current_sigma_mps));
    EXPECT_TRUE(inside(c.varying_current_time_constant_s, r.varying_current_time_constant_s));
    EXPECT_TRUE(inside(c.varying_current_direction_rad, Range(0.0, 2 * kPi)));
    const double scale = c.noise_position_m / r.sensor_noise_position_m;
    EXPECT_TRUE(inside(scale, Range(0.5 - 1e-12, 1.5 + 1e-12)));
    EXPECT_NEAR(c.noise_attitude_rad, scale * r.sensor_noise_attitude_rad, 1e-15);
    EXPECT_NEAR(c.noise_velocity_mps, scale * r.sensor_noise_velocity_mps, 1e-15);
    EXPECT_NEAR(c.noise_angular_rate_rad_s, scale * r.sensor_noise_angular_rate_rad_s, 1e-15);
    EXPECT_TRUE(inside(c.quadratic_damping_scale, r.quadratic_damping_scale));
    EXPECT_TRUE(inside(c.added_mass_scale, r.added_mass_scale));
    EXPECT_TRUE(inside(c.mass_scale, r.mass_scale));
    EXPECT_TRUE(inside(c.thruster_lag_time_constant_s, r.thruster_lag_time_constant_s));
    EXPECT_TRUE(inside(c.extra_buoyancy_n, r.extra_buoyancy_n));
  }
  for (int f : faults) EXPECT_GT(f, 850);      // ~1000 each: any thruster
  for (int q : quadrants) EXPECT_GT(q, 1300);  // ~1500 each: any direction
  EXPECT_EQ(describe_kinds(31u), "fault+current+varying_current+sensor_noise+model");
  EXPECT_EQ(describe(r), "fault 1, current 1, varying_current 1, sensor_noise 1, model 1");
}

TEST(Randomisation, TheSameSeedGivesTheSameConditionsAndOneKindDoesNotMoveAnother) {
  const EpisodeRandomisation r = everything();
  EpisodeRandomisation fault_only;
  fault_only.fault_probability = r.fault_probability;
  fault_only.fault_efficiency = r.fault_efficiency;
  std::mt19937_64 a(21), b(21), c(21);
  for (int i = 0; i < 500; ++i) {
    const EpisodeConditions x = sample_conditions(r, kThrusters, a);
    const EpisodeConditions y = sample_conditions(r, kThrusters, b);
    EXPECT_EQ(x.kinds, y.kinds);
    EXPECT_EQ(x.thruster_efficiency, y.thruster_efficiency);
    EXPECT_EQ(x.current_ned_mps, y.current_ned_mps);
    EXPECT_EQ(x.noise_position_m, y.noise_position_m);
    EXPECT_EQ(x.mass_scale, y.mass_scale);
    // Only the fault on: the same faults on the same episodes, the thrust scale aside.
    const EpisodeConditions z = sample_conditions(fault_only, kThrusters, c);
    EXPECT_EQ(z.kinds, x.kinds & EpisodeConditions::kFault);
    if (z.kinds != 0) {
      EXPECT_EQ(z.fault_thruster, x.fault_thruster);
      EXPECT_DOUBLE_EQ(
          z.thruster_efficiency[static_cast<std::size_t>(z.fault_thruster)] * x.thrust_scale,
          x.thruster_efficiency[static_cast<std::size_t>(x.fault_thruster)]);
    }
  }
  // A fixed number of draws: the streams stay in step whatever was configured.
  EXPECT_EQ(a(), c());
  std::mt19937_64 off(21);
  for (int i = 0; i < 500; ++i) sample_conditions(EpisodeRandomisation{}, kThrusters, off);
  EXPECT_EQ(b(), off());
}

std::string refusal(const EpisodeRandomisation& r) {
  try {
    r.validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

// A fault thruster asked for takes the fault the draw would have placed elsewhere: the same
// kinds and efficiency, the same number of draws; one that is not a thruster is refused.
TEST(Randomisation, AFaultCanBeGivenItsThruster) {
  EpisodeRandomisation r;
  r.fault_probability = 1.0;
  std::mt19937_64 a(5), b(5);
  for (int i = 0; i < 50; ++i) {
    const EpisodeConditions drawn = sample_conditions(r, kThrusters, a);
    const EpisodeConditions given = sample_conditions(r, kThrusters, b, i % kThrusters);
    ASSERT_EQ(given.fault_thruster, i % kThrusters);
    EXPECT_EQ(given.kinds, drawn.kinds);
    EXPECT_EQ(given.thruster_efficiency[static_cast<std::size_t>(i % kThrusters)],
              drawn.thruster_efficiency[static_cast<std::size_t>(drawn.fault_thruster)]);
  }
  EXPECT_EQ(a(), b());
  EXPECT_THROW(sample_conditions(r, kThrusters, a, kThrusters), std::invalid_argument);
  EXPECT_THROW(sample_conditions(r, kThrusters, a, -2), std::invalid_argument);
}

TEST(Randomisation, UnusableSettingsAreRefusedNamingTheKey) {
  EXPECT_EQ(refusal(everything()), "");
  EpisodeRandomisation r;
  r.model_probability = -0.1;
  EXPECT_EQ(refusal(r), "task.randomise.model_probability must be in [0, 1]");
  r = EpisodeRandomisation{};
  r.fault_efficiency = Range(0.5, 1.5);
  EXPECT_NE(refusal(r).find("task.randomise.fault_efficiency must lie in [0, 1]"),
            std::string::npos);
  r = EpisodeRandomisation{};
  r.current_speed_mps = Range(0.5, 0.1);
  EXPECT_NE(refusal(r).find("task.randomise.current_speed_mps must be [low, high]"),
            std::string::npos);
  r = EpisodeRandomisation{};
  r.thrust_scale = Range(0.7, 1.2);  // an efficiency above 1
  EXPECT_NE(refusal(r).find("task.randomise.thrust_scale"), std::string::npos);
  r = EpisodeRandomisation{};
  r.mass_scale = Range(0.0, 1.2);
  EXPECT_NE(refusal(r).find("task.randomise.mass_scale"), std::string::npos);
  r = EpisodeRandomisation{};
  r.thruster_lag_time_constant_s = Range(0.0, 0.6);  // 0 would mean "the file's"
  EXPECT_NE(refusal(r).find("task.randomise.thruster_lag_time_constant_s"), std::string::npos);
  r = EpisodeRandomisation{};
  r.sensor_noise_attitude_rad = std::nan("");
  EXPECT_NE(refusal(r).find("task.randomise.sensor_noise_attitude_rad"), std::string::npos);
  TaskConfig task;
  task.randomise.varying_current_time_constant_s = Range(0.0, 10.0);
  EXPECT_THROW(task.validate(), std::invalid_argument);
}

std::string read_error(const std::string& yaml) {
  TaskConfig task;
  try {
    read_task_config(config::Section("run.yaml", "task", YAML::Load(yaml)), task);
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Randomisation, TheTaskSectionReadsItAndNamesBadKeys) {
  TaskConfig task;
  read_task_config(config::Section("run.yaml", "task",
                                   YAML::Load("randomise:\n"
                                              "  fault_probability: 0.25\n"
                                              "  fault_efficiency: [0, 0.1]\n"
                                              "  extra_buoyancy_n: [-10, 20]\n")),
                   task);
  EXPECT_EQ(task.randomise.fault_probability, 0.25);
  EXPECT_EQ(task.randomise.fault_efficiency, Range(0.0, 0.1));
  EXPECT_EQ(task.randomise.extra_buoyancy_n, Range(-10.0, 20.0));
  EXPECT_NE(
      read_error("randomise:\n  fault_probability: 1.5\n").find("task.randomise.fault_probability"),
      std::string::npos);
  EXPECT_NE(read_error("randomise:\n  mass_scale: [1.2, 1.0]\n").find("task.randomise.mass_scale"),
            std::string::npos);
  EXPECT_NE(read_error("randomise:\n  fault_chance: 0.5\n").find("fault_chance"),
            std::string::npos);
}

}  // namespace
}  // namespace auvrl::task
