// Helpers shared by the agent library's tests.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "sim/vehicle_model.hpp"

namespace auvrl::test_support {

/// A scratch directory for one test, removed at the end.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("auvrl_agent_test_" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string path(const std::string& name = "") const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

/// The cells of one CSV line (a trailing comma is an empty last cell).
inline std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

/// The project's Nessie VII vehicle file.
inline std::string vehicle_path() {
  return std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
}

/// The Nessie VII model, loaded once.
inline const sim::VehicleModel& nessie() {
  static const sim::VehicleModel model = sim::load_vehicle_file(vehicle_path());
  return model;
}

/// Every line of a CSV file, split into cells.
inline std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) rows.push_back(split(line));
  return rows;
}

}  // namespace auvrl::test_support
