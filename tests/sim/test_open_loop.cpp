// Open-loop tool: input parsing and validation, output format, agreement with step().
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "sim/open_loop.hpp"
#include "sim_test_util.hpp"  // first: see the note on Eigen warnings there

namespace auvrl::sim::test {
namespace {

const char* kInput =
    "t,f1,f2,f3,f4,f5,f6\n"
    "0,39.24,39.24,0,0,0,0\n"
    "1.5,20,-20,10,10,-5,5\n"
    "2.05,0,0,0,0,30,30\n"  // between control steps: takes effect at the step starting at 2.1
    "\n"
    "3.0,0,0,0,0,0,0\n";

std::vector<std::vector<double>> read_rows(const std::string& path, std::string& header) {
  std::istringstream in(read_text(path));
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(std::strtod(field.c_str(), nullptr));
    rows.push_back(row);
  }
  return rows;
}

/// The same run stepped directly with the library.
std::vector<VehicleState> reference_run(bool ideal) {
  const VehicleModel& m = nessie();
  ResetSettings reset;
  reset.eta << 0, 0, 5, 0, 0, 0;
  VehicleState s = make_state(m, reset);
  std::vector<VehicleState> states{s};
  for (int k = 0; k < 30; ++k) {
    ThrusterVector command = thrusts({39.24, 39.24, 0, 0, 0, 0});
    if (k >= 15) command = thrusts({20, -20, 10, 10, -5, 5});
    if (k >= 21) command = thrusts({0, 0, 0, 0, 30, 30});
    if (ideal) {
      step_ideal_thrusters(m, s, command);
    } else {
      step(m, s, command);
    }
    states.push_back(s);
  }
  return states;
}

class OpenLoopTool : public ::testing::TestWithParam<bool> {};

TEST_P(OpenLoopTool, MatchesSteppingTheLibrary) {
  const bool ideal = GetParam();
  TempDir dir;
  write_text(dir.file("in.csv"), kInput);
  OpenLoopOptions options;
  options.vehicle_path = vehicle_path("nessie7.yaml");
  options.input_csv = dir.file("in.csv");
  options.output_csv = dir.file("out.csv");
  options.ideal_thrusters = ideal;
  std::ostringstream err;
  ASSERT_EQ(run_open_loop(options, err), kOpenLoopOk) << err.str();
  EXPECT_EQ(err.str(), "");

  std::string header;
  const auto rows = read_rows(options.output_csv, header);
  EXPECT_EQ(header,
            "t,x,y,z,phi,theta,psi,u,v,w,p,q,r,thrust_1,thrust_2,thrust_3,thrust_4,thrust_5,"
            "thrust_6");
  const auto states = reference_run(ideal);
  ASSERT_EQ(rows.size(), 31u);  // t = 0, 0.1, ..., 3.0 (up to the last row's time)
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ASSERT_EQ(rows[k].size(), 19u) << "row " << k;
    const VehicleState& s = states[k];
    EXPECT_EQ(rows[k][0], s.time_s);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(rows[k][1 + i], s.eta(i)) << "row " << k;
    for (int i = 0; i < 6; ++i) EXPECT_EQ(rows[k][7 + i], s.nu(i)) << "row " << k;
    for (int i = 0; i < 6; ++i) EXPECT_EQ(rows[k][13 + i], s.thrust_realised_n(i)) << "row " << k;
  }
  EXPECT_EQ(rows[0][3], 5.0);  // default start 5 m deep
}

INSTANTIATE_TEST_SUITE_P(StepAndIdeal, OpenLoopTool, ::testing::Bool());

struct BadInput {
  const char* label;
  const char* text;
  const char* expected;  ///< substring of the error
};

void PrintTo(const BadInput& b, std::ostream* os) { *os << b.label; }

class OpenLoopBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(OpenLoopBadInput, NamesLineAndColumn) {
  const BadInput& b = GetParam();
  TempDir dir;
  const std::string path = dir.file("in.csv");
  write_text(path, b.text);
  try {
    read_open_loop_csv(path, 6);
    FAIL() << "accepted: " << b.label;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + b.expected), std::string::npos) << e.what();
  }
  // Through the front-end function: exit code and message, no output written.
  OpenLoopOptions options;
  options.vehicle_path = vehicle_path("nessie7.yaml");
  options.input_csv = path;
  options.output_csv = dir.file("out.csv");
  std::ostringstream err;
  EXPECT_EQ(run_open_loop(options, err), kOpenLoopInputError);
  EXPECT_NE(err.str().find(path + b.expected), std::string::npos) << err.str();
}

INSTANTIATE_TEST_SUITE_P(
    Validation, OpenLoopBadInput,
    ::testing::Values(
        BadInput{"not a number", "t,f1,f2,f3,f4,f5,f6\n0,1,2,3,4,5,6\n1,1,x2,3,4,5,6\n",
                 ":3: column 3 (f2): 'x2' is not a number"},
        BadInput{"missing column", "t,f1,f2,f3,f4,f5,f6\n0,1,2,3,4,5\n", ":2: expected 7 columns"},
        BadInput{"wrong header", "t,f1,f2,f3,f4,f5\n0,1,2,3,4,5\n", ":1: expected the header"},
        BadInput{"time going back",
                 "t,f1,f2,f3,f4,f5,f6\n0,0,0,0,0,0,0\n2,0,0,0,0,0,0\n"
                 "1,0,0,0,0,0,0\n",
                 ":4: column 1 (t): times must increase"},
        BadInput{"non-finite", "t,f1,f2,f3,f4,f5,f6\n0,0,0,inf,0,0,0\n",
                 ":2: column 4 (f3): expected a finite number"},
        BadInput{"empty field", "t,f1,f2,f3,f4,f5,f6\n0,0,0,0,0,0,\n",
                 ":2: column 7 (f6): '' is not a number"},
        BadInput{"no rows", "t,f1,f2,f3,f4,f5,f6\n", ":1: no command rows"}));

TEST(OpenLoop, MissingVehicleFileIsReported) {
  TempDir dir;
  write_text(dir.file("in.csv"), kInput);
  OpenLoopOptions options;
  options.vehicle_path = dir.file("no_such_vehicle.yaml");
  options.input_csv = dir.file("in.csv");
  options.output_csv = dir.file("out.csv");
  std::ostringstream err;
  EXPECT_EQ(run_open_loop(options, err), kOpenLoopInputError);
  EXPECT_NE(err.str().find("no_such_vehicle.yaml"), std::string::npos) << err.str();
}

TEST(OpenLoop, ExplicitDurationAndBlowUp) {
  const VehicleModel& m = nessie();
  OpenLoopCommands commands;
  commands.time_s = {0.0};
  commands.thrust_command_n = {thrusts({39.24, 39.24, 0, 0, 0, 0})};
  ResetSettings reset = reset_at_depth(5);
  const auto run = run_open_loop_commands(m, reset, commands, 2.0, true);
  EXPECT_EQ(run.samples.size(), 21u);
  EXPECT_NEAR(run.samples.back().time_s, 2.0, 1e-12);

  VehicleModel fragile = m;
  fragile.blow_up.max_linear_speed_mps = 0.5;
  const auto blown = run_open_loop_commands(fragile, reset, commands, 10.0, true);
  EXPECT_EQ(blown.status, StateStatus::kSpeedLimit);
  EXPECT_LT(blown.samples.size(), 101u);
  EXPECT_LE(blown.samples.back().nu(0), 0.5);
}

}  // namespace
}  // namespace auvrl::sim::test
