// Reading what a running or finished run leaves on disk (CSV tables, pid files, logs), for the
// tests that start the real processes and wait for them.
#pragma once

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace auvrl::test_support {

/// Rows of a CSV file as maps from column to text; a row with the wrong number of cells (one
/// still being written) is left out.
inline std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  const auto split = [](const std::string& text) {
    std::vector<std::string> cells;
    std::stringstream ss(text);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    return cells;
  };
  if (std::getline(in, line)) header = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    if (cells.size() != header.size()) continue;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size(); ++i) row[header[i]] = cells[i];
    rows.push_back(row);
  }
  return rows;
}

/// The whole file as text ("" if it cannot be read).
inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The process id in a pid file, or -1.
inline int read_pid(const std::filesystem::path& path) {
  std::ifstream in(path);
  int pid = -1;
  in >> pid;
  return pid;
}

/// Polls condition every 100 ms for up to `seconds`; its last value.
inline bool wait_for(const std::function<bool()>& condition, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return condition();
}

/// Writes a copy of config_dir/presets/<preset>.yaml to out_path for a test run: the vehicle
/// path made absolute, then `edit` applied to every line (it may append lines with "\n").
/// Returns out_path.
inline std::string write_preset_copy(const std::string& config_dir, const std::string& preset,
                                     const std::string& out_path,
                                     const std::function<void(std::string& line)>& edit) {
  std::ifstream in(config_dir + "/presets/" + preset + ".yaml");
  std::ofstream out(out_path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("vehicle:", 0) == 0) line = "vehicle: " + config_dir + "/vehicles/nessie7.yaml";
    edit(line);
    out << line << "\n";
  }
  return out_path;
}

}  // namespace auvrl::test_support
