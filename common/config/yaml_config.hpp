// Strict reading of YAML configuration files (presets, run configurations): every value has a
// default in the struct it fills, every key present must be one the reader knows (a typo is an
// error, never a silent default), and every error names the file, the dotted key and the line.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace auvrl::config {

/// A configuration file that cannot be used; the message names file, key and line.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
  /// key: the dotted key at fault; detail: what is wrong with it (without file and line).
  ConfigError(const std::string& message, std::string key, std::string detail)
      : std::runtime_error(message), key_(std::move(key)), detail_(std::move(detail)) {}
  const std::string& key() const { return key_; }  ///< "" when the error names no key
  const std::string& detail() const { return detail_; }

 private:
  std::string key_;
  std::string detail_;
};

/// A map in a configuration file. read() fills a target only when the key is present; finish()
/// rejects any key that no read() asked for.
class Section {
 public:
  Section(std::string file, std::string path, YAML::Node node);

  bool has(const std::string& key) const;
  void read(const std::string& key, double& value);
  void read(const std::string& key, float& value);
  void read(const std::string& key, int& value);
  void read(const std::string& key, std::int64_t& value);
  void read(const std::string& key, std::uint64_t& value);
  void read(const std::string& key, bool& value);
  void read(const std::string& key, std::string& value);
  void read(const std::string& key, std::vector<int>& value);
  /// A list of exactly N numbers (Eigen::Vector3d: [x, y, z]).
  template <int N>
  void read(const std::string& key, Eigen::Matrix<double, N, 1>& value) {
    read_numbers(key, value.data(), N);
  }
  /// An N x N matrix: N rows of N numbers, or N numbers for its diagonal (the rest zero).
  template <int N>
  void read(const std::string& key, Eigen::Matrix<double, N, N>& value) {
    static_assert(N > 1, "a 1x1 matrix is a number");
    read_square(key, value.data(), N);
  }
  /// A list of lists of numbers (e.g. schedule knots [[episode, beta], ...]).
  void read(const std::string& key, std::vector<std::vector<double>>& value);
  /// A sub-map (empty when absent).
  Section child(const std::string& key);
  /// A list of maps, one Section per entry (paths "key[0]", "key[1]", ...; none when absent);
  /// fails unless it has min_items..max_items entries (checked before any entry is read).
  std::vector<Section> items(const std::string& key, std::size_t min_items = 0,
                             std::size_t max_items = static_cast<std::size_t>(-1));
  /// Marks keys as known without reading them (sections other processes read).
  void ignore(std::initializer_list<const char*> keys);
  void ignore_key(const std::string& key) { read_.insert(key); }
  /// Throws ConfigError for any key nobody read (or a key that is no name: "? [a, b]").
  void finish() const;

  /// Throws ConfigError naming file, dotted key and line (of the key's value; of the map
  /// itself when the key is absent).
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  const std::string& file() const { return file_; }
  std::string key_path(const std::string& key) const;

 private:
  std::optional<YAML::Node> get(const std::string& key);
  double number(const YAML::Node& node, const std::string& key) const;
  void read_numbers(const std::string& key, double* out, int n);
  /// Column-major n x n (Eigen's layout).
  void read_square(const std::string& key, double* out, int n);
  std::int64_t integer(const YAML::Node& node, const std::string& key) const;

  std::string file_;
  std::string path_;
  YAML::Node node_;
  std::set<std::string> read_;
};

/// Reads a whole file's bytes into `text`. Returns false with `why` set ("cannot open the file",
/// "is a directory, not a file", "cannot read the file") when it cannot: a directory opens as a
/// stream and fails only on its first read, with std::ios_base::failure. Every YAML file (run,
/// mission, vehicle) is read through here.
bool read_text_file(const std::string& path, std::string& text, std::string& why);

/// Loads a YAML file whose top level is a map; throws ConfigError naming the file on a
/// missing or unreadable file or a syntax error.
Section load_file(const std::string& path);
/// The same for YAML text that arrived otherwise (a message); `origin` names it in errors.
Section load_text(const std::string& text, const std::string& origin);

}  // namespace auvrl::config

namespace auvrl::config {

/// The top-level sections of a run configuration (config/presets/*.yaml). Every process reads
/// the ones it needs and then calls finish_run_file(), which accepts these and rejects any
/// other top-level key (a misspelt section is an error, not a silently ignored block).
///   vehicle: path of the vehicle file, relative to the configuration's directory
///   task:, schedule:   common/task (every process)
///   learner:           auv_learner        actor:   auv_actor        run:   the launcher
///   transport:         the launcher (passed to every process as flags)
void finish_run_file(Section& root);

/// A path from a configuration file: absolute as is, else relative to the file's directory.
std::string resolve_path(const Section& section, const std::string& path);

}  // namespace auvrl::config
